// dlslot-bench-check: judges the CPU per frame of one or more runs of a pipeline case (dlslot-run's
// OUT/speed.yaml; each process's median over the runs) against the stored figures of the case in
// bench/baseline.yaml, or records it there.
//   dlslot-bench-check --baseline bench/baseline.yaml --case NAME --measured OUT1/speed.yaml [--measured OUT2/speed.yaml ...]
//   dlslot-bench-check ... --record "why the cost changed"
// Exit 0: every process within 15 % of its stored cost; 1: some process over (named on stderr
// and in the last line); 2: bad arguments or files.
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>

#include "dlslot/node.hpp"
#include "speed_guard.hpp"

using namespace dlslot;

namespace {

YAML::Node loadFile(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
}

std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return buf;
}

int check(int argc, char** argv) {
  std::string baseline, name, reason;
  std::vector<std::string> measured_paths;
  double tolerance = 0.15;
  CommandLine cl("dlslot-bench-check",
                 "Compares a pipeline run's CPU per frame (dlslot-run's OUT/speed.yaml) with bench/baseline.yaml.");
  cl.option("--baseline", &baseline, "the stored figures (bench/baseline.yaml)");
  cl.option("--case", &name, "which run, e.g. highway-150-lockstep-no-render");
  cl.repeated("--measured", &measured_paths, "dlslot-run's OUT/speed.yaml (repeated: each process's median over the runs)");
  cl.option("--tolerance", &tolerance, "allowed growth of a process's CPU per frame (default 0.15)");
  cl.option("--record", &reason, "store the measured figures as the case's new baseline, with this reason");
  if (!cl.parse(argc, argv)) return 0;
  if (baseline.empty() || name.empty() || measured_paths.empty())
    throw std::invalid_argument("--baseline, --case and --measured are required");
  std::vector<run::SpeedFigures> runs;
  for (const std::string& path : measured_paths) runs.push_back(run::speedFromYaml(loadFile(path), path));
  const run::SpeedFigures measured = run::medianOf(runs);

  if (!reason.empty()) {
    YAML::Node all = std::ifstream(baseline) ? loadFile(baseline) : YAML::Node(YAML::NodeType::Map);
    YAML::Node c;
    c["recorded"] = utcNow();
    c["reason"] = reason;
    c["rate_fps"] = std::round(measured.rate_fps * 100) / 100;
    c["load"] = measured.load;
    c["load"].SetStyle(YAML::EmitterStyle::Flow);
    for (const auto& [p, ms] : measured.cpu_ms) c["cpu_ms_per_frame"][p] = std::round(ms * 100) / 100;
    all[name] = c;
    YAML::Emitter e;
    e.SetDoublePrecision(4);
    e << all;
    std::ofstream f(baseline);
    f << "# Stored CPU time per frame (ms) of each process in ./dlslot bench's pipeline runs, and their\n"
         "# rate. ./dlslot bench fails, naming the process, when one costs more than 15 % over its figure\n"
         "# here. Written by `./dlslot bench --record \"REASON\"` (docs/performance.md): say why a cost grew.\n"
      << e.c_str() << "\n";
    if (!f) throw std::runtime_error("cannot write " + baseline);
    std::cerr << "bench: recorded " << name << " in " << baseline << "\n";
    return 0;
  }

  const YAML::Node all = loadFile(baseline);
  if (!all.IsMap() || !all[name])
    throw std::invalid_argument(baseline + ": no case '" + name + "' (record one with --record REASON)");
  const run::SpeedFigures stored = run::speedFromYaml(all[name], baseline + ": " + name);
  const run::SpeedVerdict v = run::compareSpeed(stored, measured, tolerance);
  std::fprintf(stderr, "bench %s: CPU per frame against %s (recorded %s)\n%s", name.c_str(), baseline.c_str(),
               all[name]["recorded"] ? all[name]["recorded"].as<std::string>().c_str() : "?", v.report.c_str());
  std::string load;
  for (double l : measured.load) load += (load.empty() ? "" : " -> ") + std::to_string(l).substr(0, 5);
  std::fprintf(stderr, "  pipeline rate %.2f frames/s, stored %.2f (wall clock, not judged; load %s)\n",
               measured.rate_fps, stored.rate_fps, load.c_str());
  if (v.over.empty()) {
    std::fprintf(stderr, "bench %s: OK\n", name.c_str());
    return 0;
  }
  std::string who;
  for (const auto& p : v.over) who += (who.empty() ? "" : ", ") + p;
  std::fprintf(stderr, "bench %s: FAILED: %s over %.0f %% of the stored CPU per frame\n", name.c_str(), who.c_str(),
               100 * tolerance);
  return 1;
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-bench-check", [&] { return check(argc, argv); }); }
