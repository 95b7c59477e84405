// The speed guard of `./dlslot bench`: each process's CPU time per frame in a pipeline run
// (dlslot-run's OUT/speed.yaml) against the figures stored in bench/baseline.yaml. CPU time is
// the measure, not the rate: on a shared machine a process's CPU time per frame moves by a few
// per cent with the load, its wall-clock rate by a factor of three.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace dlslot::run {

struct SpeedFigures {
  std::map<std::string, double> cpu_ms;  // process -> CPU ms per played frame
  double rate_fps = 0;                   // pipeline rate (wall clock: printed, not judged)
  std::vector<double> load;              // 1-minute load average at the start and end of the play
};

// `node` holds cpu_ms_per_frame (a map), rate_fps and load; `where` names it in errors
// (std::invalid_argument: "FILE: KEY: expected ...").
SpeedFigures speedFromYaml(const YAML::Node& node, const std::string& where);

// Each process's median CPU per frame over several runs of the same case (and the median rate;
// the load of the first run): a process's CPU per frame moves 10-30 % from run to run on the
// shared machine (the player 2.6-3.2 ms, the mapper beside the renderer 3.4-4.9 ms, in 8-10
// alternating rounds), as much as the guard's tolerance, so one run is not a figure. A process
// missing from a run counts over the runs that have it.
SpeedFigures medianOf(const std::vector<SpeedFigures>& runs);

struct SpeedVerdict {
  std::vector<std::string> over;  // processes over their limit
  std::string report;             // one line per process: measured, stored, change, limit
};

// A process fails when it costs more than (1 + tolerance) x its stored CPU per frame and more
// than floor_ms above it: the floor is a process's start-up and exit (libraries, config, LCM's
// socket), which differ by ~30 ms between two runs on the shared machine, 0.2 ms a frame over
// 150 frames, so a 1 ms process is not failed by them. A stored process that was not measured
// fails too (the stage vanished or crashed before reporting).
SpeedVerdict compareSpeed(const SpeedFigures& stored, const SpeedFigures& measured, double tolerance = 0.15,
                          double floor_ms = 0.2);

}  // namespace dlslot::run
