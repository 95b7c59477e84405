// dlslot-run: runs the whole DL-SLOT pipeline on one sequence and collects every output.
//
// Starts lcm-logger, the renderer, backend, tracker, odometry and (--detector geometric, the
// default without detection files) dlslot-detector, waits until each reports on
// PROCESS_STATUS, then plays the sequence (lockstep on SLOT_STATE by default). It watches every
// process: one that dies, or a pipeline that stops making progress, ends the run with an error
// naming the process and its last log lines; so does a process whose heartbeat (PROCESS_STATUS,
// once a second) stops for --heartbeat-timeout seconds (stopped or hung). At the end it stops
// everything cleanly, runs the evaluator, and accounts for every played frame per process
// (frame_accounting.hpp): a run that lost frames says so in its last line and exits 4 unless
// --allow-loss. Run it inside scripts/netns-run (./dlslot run does) unless --lcm-url is given.
// --foxglove [PORT] also starts dlslot-foxglove, the live Foxglove bridge (not counted in the
// frame accounting: it only watches).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <yaml-cpp/yaml.h>

#include "dlslot/input_error.hpp"

#include "dlslot/frame_accounting.hpp"
#include "dlslot/kitti.hpp"
#include "dlslot/message_auth.hpp"
#include "dlslot/node.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/progress.hpp"
#include "dlslot/receive_buffer.hpp"
#include "dlslot/slot_state_t.hpp"
#include "scan_folder.hpp"
#include "end_wait.hpp"
#include "supervisor.hpp"

using namespace dlslot;
namespace fs = std::filesystem;

namespace {

// The paper's comparison modes (Table I) as odometry and backend settings.
struct ModeSettings {
  std::string odometry, backend;
};
ModeSettings settingsFor(const std::string& mode) {
  if (mode == "slot") return {"aloam-filtered", "slot"};
  if (mode == "aloam") return {"aloam", "odometry-only"};
  if (mode == "aloam-filtered") return {"aloam-filtered", "odometry-only"};
  if (mode == "two-stage") return {"aloam-filtered", "two-stage"};
  throw std::invalid_argument("--mode: expected slot, aloam, aloam-filtered or two-stage, got '" + mode + "'");
}

// Where DETECTIONS come from: "files" (the player plays detection files; a scenario's are the
// simulator's) or "geometric" (dlslot-detector on the scans). Without --detector: files when
// there are any (--detections, or a scenario's), else the geometric detector; said on stderr.
std::string detectionSource(const std::string& requested, bool have_files, bool scenario) {
  if (requested == "files") {
    if (!have_files) std::cerr << "detections: --detector files without --detections: DETECTIONS stay empty\n";
    return requested;
  }
  if (requested == "geometric") {
    if (have_files && !scenario)
      throw std::invalid_argument("--detector geometric and --detections exclude each other");
    std::cerr << "detections: dlslot-detector (geometric) on the scans\n";
    return requested;
  }
  if (!requested.empty())
    throw std::invalid_argument("--detector: expected geometric or files, got '" + requested + "'");
  if (have_files) {
    std::cerr << "detections: " << (scenario ? "the simulator's" : "from --detections")
              << " files (--detector geometric to detect from the scans instead)\n";
    return "files";
  }
  std::cerr << "detections: no --detections given, so dlslot-detector (geometric) detects from the scans "
               "(--detector files to run without detections)\n";
  return "geometric";
}

// Writes the run's config, OUT/config.yaml, which every process then reads; returns its path.
std::string writeRunConfig(const YAML::Node& cfg, const std::string& what, const std::string& out) {
  const std::string path = out + "/config.yaml";
  std::ofstream f(path);
  f << "# " << what << "\n" << cfg << "\n";
  if (!f) throw std::runtime_error(path + ": cannot write");
  return path;
}

// The run's config for a folder of the user's scans: the odometry's beam model (and the
// detector's top beam) from the sensor calibration, or estimated from the first scan. Written to
// OUT/config.yaml, which every process then reads.
std::string sensorConfig(const std::string& config, const player::SensorCalibration& calib,
                         const player::ScanFolder& folder, const std::string& out) {
  YAML::Node cfg = YAML::LoadFile(config);
  std::string model = calib.beam_model;
  int beams = calib.beams;
  double top = calib.top_elevation_deg, bottom = calib.bottom_elevation_deg;
  if (model == "estimate") {
    const player::BeamLayout b = player::estimateBeams(player::readScanFile(folder.files.front()));
    beams = b.beams, top = b.top_elevation_deg, bottom = b.bottom_elevation_deg;
    std::cerr << "sensor: " << b.beams << " beams estimated from " << folder.files.front() << ", " << bottom << " .. "
              << top << " deg" << (b.uniform ? ", evenly spaced" : ", unevenly spaced") << "\n";
    if (b.uniform)
      model = "uniform";
    else if (b.beams >= 60 && b.beams <= 64 && std::abs(top - 2.0) < 0.5 && std::abs(bottom + 24.3) < 1.0)
      model = "hdl64";  // the HDL-64E's two blocks of beam spacing
    else
      throw InputError(calib.path, 0, "beams: estimated " + std::to_string(b.beams) +
                                          " unevenly spaced beams the odometry has no model for; give "
                                          "beams: {model: uniform, count, elevation_deg} or hdl64");
  }
  // The user's sensor stores its points on their rays unless its calibration says otherwise (the
  // pipeline's default, 0.22 deg, is KITTI's HDL-64E).
  cfg["lidar"]["vertical_angle_error_deg"] = calib.vertical_angle_error_deg;
  YAML::Node features = cfg["odometry"]["features"];
  features["beam_model"] = model;
  if (model == "uniform") {
    features["num_beams"] = beams;
    features["min_vertical_deg"] = bottom;
    features["max_vertical_deg"] = top;
    cfg["detector"]["classes"]["top_beam_deg"] = top;
  }
  const std::string path = writeRunConfig(cfg, config + " with the sensor of " + calib.path, out);
  std::cerr << "sensor: odometry beam model " << model
            << (model == "uniform" ? " (" + std::to_string(beams) + " beams)" : std::string()) << "; config " << path << "\n";
  return path;
}

// The run's config for a simulated sequence: the simulator's description of its scans
// (ROOT/lidar.yaml: sweep timing, vertical-angle error) in place of the config's lidar section,
// written to OUT/config.yaml, which every process then reads.
std::string simulatedSensorConfig(const std::string& config, const std::string& root, const std::string& out) {
  const std::string lidar_file = root + "/lidar.yaml";
  YAML::Node cfg = YAML::LoadFile(config);
  const YAML::Node lidar = YAML::LoadFile(lidar_file)["lidar"];
  if (!lidar || !lidar.IsMap()) throw InputError(lidar_file, 0, "expected a 'lidar' section");
  for (const auto& kv : lidar) cfg["lidar"][kv.first.as<std::string>()] = kv.second;
  const std::string path = writeRunConfig(cfg, config + " with the simulated sensor of " + lidar_file, out);
  std::cerr << "sensor: the simulator's lidar (sweep " << lidar["sweep_period_s"].as<double>() << " s, vertical-angle error "
            << lidar["vertical_angle_error_deg"].as<double>() << " deg); config " << path << "\n";
  return path;
}

std::string binDir() { return fs::read_symlink("/proc/self/exe").parent_path().string(); }

// Runs a command to completion with output to log; returns its exit code.
int runToEnd(run::Supervisor& sup, const std::string& name, const std::vector<std::string>& argv,
             const std::string& log) {
  sup.start(name, argv, log);
  while (sup.running(name)) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return sup.stop(name);
}

// The 1-minute load average (-1 when unknown): a wall-clock rate means little without it.
double loadAverage() {
  std::ifstream in("/proc/loadavg");
  double load = -1;
  in >> load;
  return in ? load : -1;
}

// OUT/speed.yaml: what `./dlslot bench` compares with bench/baseline.yaml (dlslot-bench-check).
void writeSpeed(const std::string& path, const std::vector<std::pair<std::string, double>>& cpu_ms, double rate,
                double load_before, double load_after) {
  std::ofstream f(path);
  f << "# dlslot-run: CPU time per played frame of each process (ms), the pipeline rate (frames/s)\n"
    << "# and the 1-minute load average at the start and the end of the play.\n";
  f << "rate_fps: " << rate << "\nload: [" << load_before << ", " << load_after << "]\ncpu_ms_per_frame:\n";
  for (const auto& [p, ms] : cpu_ms) f << "  " << p << ": " << ms << "\n";
  if (!f) throw std::runtime_error("cannot write " + path);
}

struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "--foxglove" may come without its port: the default port is put in, so the option parser
// (which wants a value) sees "--foxglove 8765".
std::vector<std::string> withFoxglovePort(int argc, char** argv) {
  std::vector<std::string> a(argv, argv + argc);
  for (size_t i = 1; i < a.size(); ++i)
    if (a[i] == "--foxglove" && (i + 1 == a.size() || a[i + 1].rfind("--", 0) == 0)) a.insert(a.begin() + i + 1, "8765");
  return a;
}

int runPipeline(int argc, char** argv) {
  std::vector<std::string> arg_text = withFoxglovePort(argc, argv);
  std::vector<char*> arg_ptrs;
  for (auto& a : arg_text) arg_ptrs.push_back(a.data());
  argc = static_cast<int>(arg_ptrs.size());
  argv = arg_ptrs.data();
  int foxglove_port = -1;
  std::string input, sensor_calib;
  std::string root, sequence = "0000", scenario, mode = "slot", config = "config/dlslot.yaml", out, lcm_url, detector;
  std::vector<std::string> detections;
  constexpr int kNotGiven = std::numeric_limits<int>::min();
  int frames = kNotGiven, seed = 1, in_flight = 2;
  double speed = std::numeric_limits<double>::quiet_NaN(), stall_s = 60, start_timeout_s = 30, heartbeat_s = 10;
  bool no_eval = false, no_render = false, no_map = false, quiet = false, allow_loss = false, insecure = false;
  std::string key_file, make_key;
  CommandLine cl("dlslot-run", "Runs player, odometry, tracker, backend, renderer and lcm-logger on one sequence.");
  cl.option("--kitti", &root, "KITTI root (holding training/ or sequences/)");
  cl.option("--sequence", &sequence, "sequence (default 0000)");
  cl.repeated("--detections", &detections, "detection file or directory");
  cl.option("--detector", &detector,
            "geometric (dlslot-detector on the scans) | files (--detections, a scenario's simulated ones); "
            "default: files when there are any, else geometric");
  cl.option("--scenario", &scenario, "simulate this scenario (name or YAML) first, then run on it");
  cl.option("--input", &input, "a folder of your own .pcd or .bin scans with times.txt (docs/data-formats.md)");
  cl.option("--calib", &sensor_calib, "with --input: the sensor's YAML calibration");
  cl.option("--frames", &frames, "frames to simulate (with --scenario) or to play, >= 1 (default: all)");
  cl.option("--seed", &seed, "simulator seed (default 1)");
  cl.option("--mode", &mode, "slot | aloam | aloam-filtered | two-stage (default slot)");
  cl.option("--config", &config, "YAML config (default config/dlslot.yaml)");
  cl.option("--out", &out, "output directory");
  cl.option("--lcm-url", &lcm_url, "LCM URL for every process (default: $LCM_DEFAULT_URL)");
  cl.option("--speed", &speed, "rate mode at this real-time factor (> 0) instead of lockstep");
  cl.option("--stall-timeout", &stall_s, "seconds without progress before the run fails (default 60)");
  cl.option("--heartbeat-timeout", &heartbeat_s,
            "seconds without a process's PROCESS_STATUS before it counts as stalled and the run fails (default 10)");
  cl.option("--in-flight", &in_flight,
            "lockstep: frames the player keeps ahead of SLOT_STATE (default 2: the odometry of t+1 overlaps the "
            "backend's t, same results; 1: strict lockstep)");
  cl.flag("--allow-loss", &allow_loss, "exit 0 even when frames were lost (they are still reported)");
  cl.flag("--no-eval", &no_eval, "skip the evaluation");
  cl.flag("--no-render", &no_render, "do not start the renderer");
  cl.flag("--no-map", &no_map, "do not start the mapper (no map.pcd, map.png, trajectory_map_*)");
  cl.flag("--quiet", &quiet, "no progress line");
  cl.option("--key", &key_file,
            "authenticate the run's messages with this key file (0600; the same file on every machine of the run); "
            "default: a fresh key per run, kept as run.key in --out");
  cl.flag("--insecure", &insecure, "no message authentication: any host on the LCM URL can publish into the run");
  cl.option("--make-key", &make_key, "write a fresh key file (0600) for --key and exit");
  cl.option("--foxglove", &foxglove_port,
            "[PORT] also serve the live run to Foxglove (dlslot-foxglove, WebSocket on 127.0.0.1:PORT, default 8765)");
  if (!cl.parse(argc, argv)) return 0;
  const bool foxglove = foxglove_port >= 0;
  if (!make_key.empty()) {
    const RunKey key = makeRunKey();
    writeKeyFile(make_key, key);
    std::cout << "wrote key " << make_key << " (run id " << key.runIdHex() << "); give it to every machine with --key\n";
    return 0;
  }
  if (insecure && !key_file.empty()) throw std::invalid_argument("--insecure and --key exclude each other");
  // Not given: all frames, lockstep. Given, they must mean something (--frames -3 once played
  // everything, --speed 0, -1 or nan meant lockstep without a word).
  if (frames == kNotGiven)
    frames = -1;
  else if (frames <= 0)
    throw std::invalid_argument("--frames: expected a number of frames >= 1, got " + std::to_string(frames));
  if (std::isnan(speed))
    speed = 0;  // lockstep
  else if (!(speed > 0))
    throw std::invalid_argument("--speed: expected a real-time factor > 0, got " + std::to_string(speed) +
                                " (lockstep, the default, needs no --speed)");
  const std::pair<const char*, double> durations[] = {
      {"--stall-timeout", stall_s}, {"--heartbeat-timeout", heartbeat_s}};
  for (const auto& [name, v] : durations)
    if (!(v > 0)) throw std::invalid_argument(std::string(name) + ": expected seconds > 0, got " + std::to_string(v));
  // A heartbeat comes once a second: a timeout under two of them fails a healthy run.
  if (heartbeat_s < 2)
    throw std::invalid_argument("--heartbeat-timeout: expected >= 2 s (processes report once a second), got " +
                                std::to_string(heartbeat_s));
  if (out.empty()) throw std::invalid_argument("--out DIR is required");
  if (in_flight < 1) throw std::invalid_argument("--in-flight: expected an integer >= 1");
  config = fs::absolute(findConfigFile(config)).string();  // the children get the same file from any directory
  if (int(!root.empty()) + int(!scenario.empty()) + int(!input.empty()) != 1)
    throw std::invalid_argument("give one of --kitti ROOT, --scenario NAME or --input DIR --calib FILE");
  if (!input.empty() && sensor_calib.empty()) throw std::invalid_argument("--input needs --calib FILE");
  const ModeSettings ms = settingsFor(mode);
  const std::string source = detectionSource(detector, !detections.empty() || !scenario.empty(), !scenario.empty());
  const bool geometric = source == "geometric";
  const std::string bin = binDir();
  fs::create_directories(out + "/logs");
  out = fs::canonical(out).string();
  const std::string logs = out + "/logs";
  run::Supervisor sup;

  // 0. The run's key (message_auth.hpp): every child finds it through $DLSLOT_KEY_FILE, never on
  // a command line; the run folder keeps it so the log can be verified (and replayed) later.
  const std::string run_key = out + "/" + kRunKeyFile;
  if (insecure) {
    fs::remove(run_key);  // an old run's key would make the readers refuse this run's plain log
    useNoKey();
    std::cerr << "authentication: off (--insecure): anything on the LCM URL can publish into this run\n";
  } else {
    const RunKey key = key_file.empty() ? makeRunKey() : readKeyFile(fs::absolute(key_file).string());
    if (key_file.empty() || fs::absolute(key_file) != fs::absolute(run_key)) writeKeyFile(run_key, key);
    useKeyFile(run_key);
    std::cerr << "authentication: run key " << run_key << " (run " << key.runIdHex() << ")"
              << (key_file.empty() ? "" : ", from " + key_file) << "\n";
  }

  // 1. The config is checked by every process before anything starts.
  {
    ConfigSection cfg = loadConfig(config);  // throws a clear ConfigError
    (void)cfg;
    if (!input.empty()) {
      input = fs::absolute(input).string();
      sensor_calib = fs::absolute(sensor_calib).string();
      const player::SensorCalibration calib = player::readSensorCalibration(sensor_calib);
      config = sensorConfig(config, calib, player::openScanFolder(input, calib), out);
    } else {
      fs::copy_file(config, out + "/config.yaml", fs::copy_options::overwrite_existing);
    }
    for (const std::string p : {"player", "detector", "odometry", "tracker", "backend", "renderer", "mapper", "foxglove"}) {
      if ((no_render && p == "renderer") || (!geometric && p == "detector") || (!foxglove && p == "foxglove") ||
          (no_map && p == "mapper"))
        continue;
      const std::string log = logs + "/check-" + p + ".log";
      if (runToEnd(sup, "check-" + p, {bin + "/dlslot-" + p, "--config", config, "--check-config"}, log) != 0)
        throw ConfigError("dlslot-" + p + " refused the config:\n" + run::readText(log));
    }
  }

  // 2. Simulate when asked.
  if (!scenario.empty()) {
    root = out + "/data";
    std::vector<std::string> sim = {bin + "/dlslot-sim", "--scenario", scenario, "--out", root, "--seed",
                                    std::to_string(seed), "--sequence", sequence};
    if (frames > 0) sim.insert(sim.end(), {"--frames", std::to_string(frames)});
    std::cerr << "simulating " << scenario << " ...\n";
    if (runToEnd(sup, "sim", sim, logs + "/sim.log") != 0)
      throw Failure("dlslot-sim failed:\n" + sup.tail("sim"));
    detections = geometric ? std::vector<std::string>{} : std::vector<std::string>{root + "/detections/sim"};
    config = simulatedSensorConfig(config, root, out);
  }
  const int num_frames = input.empty() ? kitti::locateSequence(root, sequence).num_frames
                                       : static_cast<int>(player::openScanFolder(input, player::readSensorCalibration(sensor_calib)).files.size());
  const int last_frame = (frames > 0 && scenario.empty()) ? std::min(frames, num_frames) - 1 : num_frames - 1;

  // 3. Start the pipeline, consumers first.
  Channels channels;
  loadPipelineConfig(config, channels);
  Node node("launcher", lcm_url, channels);
  std::map<std::string, process_status_t> health;
  std::map<std::string, Node::Clock::time_point> heard;               // last heartbeat per process
  std::map<std::string, std::vector<std::pair<double, int64_t>>> rss;  // (s since start, kB) per process
  int slot_frames = 0, slot_last = -1;
  const auto run_start = Node::Clock::now();
  auto last_progress = run_start, last_slot_time = last_progress;
  node.subscribe<process_status_t>(channels.status, [&](const process_status_t& s) {
    health[s.name] = s;
    const auto now = Node::Clock::now();
    heard[s.name] = now;
    if (const int64_t kb = statusCounter(s, "rss_kb"); kb > 0)
      rss[s.name].emplace_back(std::chrono::duration<double>(now - run_start).count(), kb);
  });
  node.subscribeFrames<slot_state_t>(channels.slot_state, [&](const slot_state_t& s) {
    ++slot_frames;
    slot_last = s.frame;
    last_progress = last_slot_time = Node::Clock::now();
  });
  // Another run on this LCM URL: its processes report once a second. Heard before ours start
  // (accepted, or refused as another run's or unauthenticated), it would take our messages for
  // its own or stall on them: refuse to start, naming the URL.
  {
    const auto refusedStatus = [&] {
      int64_t n = 0;
      for (const auto& [key, count] : node.status().refusals())
        if (key.rfind(channels.status + ".", 0) == 0) n += count;
      return n;
    };
    node.spinUntil([&] { return !health.empty() || refusedStatus() > 0; }, 1.2);
    if (!health.empty() || refusedStatus() > 0) {
      std::string who;
      for (const auto& [name, st] : health) who += " " + name + " (pid " + std::to_string(st.pid) + ")";
      if (who.empty()) who = " " + std::to_string(refusedStatus()) + " PROCESS_STATUS messages of another run";
      const char* env = std::getenv("LCM_DEFAULT_URL");
      const std::string url = !lcm_url.empty() ? lcm_url : env ? env : "LCM's default";
      throw Failure("another DL-SLOT run is using the LCM URL " + url + ": heard" + who +
                    ". Give each run its own port (--lcm-url udpm://239.255.76.67:PORT?ttl=0) or wait for it to end");
    }
  }
  std::vector<std::string> common = {"--config", config};
  if (!lcm_url.empty()) common.insert(common.end(), {"--lcm-url", lcm_url});
  auto args = [&](const std::string& exe, std::vector<std::string> extra) {
    std::vector<std::string> a = {exe};
    a.insert(a.end(), common.begin(), common.end());
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  std::vector<std::string> logger = {"/usr/bin/lcm-logger", "--quiet", "--force", out + "/run.lcmlog"};
  if (!lcm_url.empty()) logger.insert(logger.begin() + 1, "--lcm-url=" + lcm_url);
  sup.start("lcm-logger", logger, logs + "/lcm-logger.log");
  std::vector<std::string> pipeline = {"backend", "tracker", "odometry"};
  if (!no_render) {
    pipeline.insert(pipeline.begin(), "renderer");
    // Rate mode: the images keep up with the data (frames skipped when the writer is behind);
    // lockstep: every frame gets its image.
    std::vector<std::string> render_args = {"--out", out + "/bev"};
    if (speed > 0) render_args.push_back("--skip-when-behind");
    sup.start("renderer", args(bin + "/dlslot-renderer", render_args), logs + "/renderer.log");
  }
  // The mapper is not on the lockstep path (the player waits for SLOT_STATE only); it writes the
  // map files into the run folder when it is stopped. It starts below, with its wait.
  if (!no_map) pipeline.insert(pipeline.begin(), "mapper");
  // In lockstep no later frame comes before this one is solved, so the tracker and the backend may
  // wait for a frame's inputs as long as the player waits for its SLOT_STATE: going on without an
  // input that is merely slow (a loaded machine, a sanitizer build) would change the results. Their
  // two waits can come one after the other (the tracker's for ODOMETRY, then the backend's for
  // ASSOCIATIONS), and both must end before the player's: 0.4 of it each. The odometry's wait for a
  // scan's DETECTIONS runs alongside the tracker's (both wait for the same message): as long. The mapper holds a scan
  // until its SLOT_STATE, which comes after the player's waits for the frames in flight before it.
  std::vector<std::string> join, mapper_args = {"--out", out};
  if (!(speed > 0)) {
    const double player_wait = YAML::LoadFile(config)["player"]["lockstep_timeout_s"].as<double>(5.0);
    join = {"--join-timeout", std::to_string(0.4 * player_wait)};
    mapper_args.insert(mapper_args.end(), {"--join-timeout", std::to_string((in_flight + 1) * player_wait)});
  }
  if (!no_map) sup.start("mapper", args(bin + "/dlslot-mapper", mapper_args), logs + "/mapper.log");
  std::vector<std::string> backend_args = {"--mode", ms.backend};
  backend_args.insert(backend_args.end(), join.begin(), join.end());
  sup.start("backend", args(bin + "/dlslot-backend", backend_args), logs + "/backend.log");
  // Lockstep with two frames in flight: the player publishes frame t+1 once SLOT_STATE carried
  // t-1, so the odometry of t+1 runs while the tracker and the backend finish t, and the tracker
  // waits for SLOT_STATE t before associating t+1 (slot_state_gate.hpp): every process sees its
  // inputs in frame order and the tracker the optimized poses of strict lockstep, so the results
  // are the same bytes (pipeline_overlap test). --in-flight 1: strict lockstep.
  std::vector<std::string> tracker_args = join;
  if (!(speed > 0)) tracker_args.push_back("--follow-slot-state");
  sup.start("tracker", args(bin + "/dlslot-tracker", tracker_args), logs + "/tracker.log");
  std::vector<std::string> odometry_args = {"--mode", ms.odometry};
  odometry_args.insert(odometry_args.end(), join.begin(), join.end());
  sup.start("odometry", args(bin + "/dlslot-odometry", odometry_args), logs + "/odometry.log");
  if (geometric) {
    pipeline.push_back("detector");
    sup.start("detector", args(bin + "/dlslot-detector", {}), logs + "/detector.log");
  }
  // The frames every pipeline process must account for; the bridge only watches.
  const std::vector<std::string> accounted(pipeline.rbegin(), pipeline.rend());
  if (foxglove) {
    pipeline.push_back("foxglove");
    sup.start("foxglove", args(bin + "/dlslot-foxglove", {"--port", std::to_string(foxglove_port)}),
              logs + "/foxglove.log");
    std::cerr << "foxglove: live bridge on ws://127.0.0.1:" << foxglove_port << " (Foxglove: Open connection -> "
              << "Foxglove WebSocket)";
    if (const char* ns = std::getenv("DLSLOT_NETNS"); ns && std::string(ns) == "private")
      std::cerr << "; it is inside this run's private network namespace: to reach it from this machine give "
                   "--lcm-url 'udpm://239.255.76.67:7667?ttl=0'";
    std::cerr << "\n";
  }

  auto failIfDead = [&](const std::string& except) {
    while (auto e = sup.reap()) {
      if (e->name == except && e->code == 0) continue;
      std::string lines = sup.tail(e->name);
      if (lines.find_first_not_of(" \n") == std::string::npos) lines = "(it printed nothing)\n";
      // On a full disk the logger's own log (on the same disk) may hold nothing: say what can be seen.
      if (e->name == "lcm-logger") {
        std::error_code ec;
        const auto space = fs::space(out, ec);
        const auto size = fs::file_size(out + "/run.lcmlog", ec);
        lines += "run.lcmlog holds " + (ec ? std::string("nothing") : std::to_string(size) + " bytes") + "; " +
                 (space.available == static_cast<std::uintmax_t>(-1)
                      ? std::string("free space unknown")
                      : std::to_string(space.available) + " bytes free on the disk of " + out) +
                 ": a full disk or a file that cannot be written stops the logger\n";
      }
      throw Failure(e->name + " " + e->how + "; its last lines (" + sup.logPath(e->name) + "):\n" + lines);
    }
  };
  auto allUp = [&] {
    for (const auto& p : pipeline)
      if (!health.count(p)) return false;
    return true;
  };
  installSignalHandlers();
  const auto up_deadline = Node::Clock::now() + std::chrono::duration<double>(start_timeout_s);
  while (!allUp()) {
    failIfDead("");
    if (Node::Clock::now() > up_deadline) {
      std::string missing;
      for (const auto& p : pipeline)
        if (!health.count(p)) missing += " " + p;
      throw Failure("no PROCESS_STATUS within " + std::to_string(int(start_timeout_s)) + " s from:" + missing);
    }
    node.spinUntil([] { return false; }, 0.1);
  }

  // 4. Play, watching every process.
  const int64_t kernel_drops_before = udpReceiveBufferErrors();
  // A process whose heartbeat stopped: SIGSTOP, an endless loop, a deadlock.
  auto failIfSilent = [&] {
    const auto now = Node::Clock::now();
    for (const auto& p : pipeline) {
      const auto it = heard.find(p);
      if (it == heard.end() || std::chrono::duration<double>(now - it->second).count() <= heartbeat_s) continue;
      const auto h = health.find(p);
      throw Failure(p + " stalled: no PROCESS_STATUS (heartbeat) for " + std::to_string(int(heartbeat_s)) +
                    " s though it is still running (stopped or hung); its last frame " +
                    std::to_string(h == health.end() ? -1 : h->second.last_frame) + "; its last lines (" +
                    sup.logPath(p) + "):\n" + sup.tail(p) + "\nframes so far (from the last PROCESS_STATUS of each):\n" +
                    accountFrames(health, last_frame + 1, accounted).table());
    }
  };
  std::vector<std::string> play = {"--quiet", "--delay", "0.2", "--end", std::to_string(last_frame)};
  if (input.empty())
    play.insert(play.end(), {"--kitti", root, "--sequence", sequence});
  else
    play.insert(play.end(), {"--input", input, "--calib", sensor_calib});
  for (const auto& d : detections) play.insert(play.end(), {"--detections", d});
  if (geometric) play.push_back("--no-detections");
  if (speed > 0)
    play.insert(play.end(), {"--speed", std::to_string(speed)});
  else
    play.insert(play.end(), {"--lockstep", "SLOT_STATE", "--in-flight", std::to_string(in_flight)});
  sup.start("player", args(bin + "/dlslot-player", play), logs + "/player.log");
  const auto play_start = Node::Clock::now();
  const double load_before = loadAverage();
  ProgressLine progress("run " + (scenario.empty() ? sequence : scenario) + " [" + mode + "]", last_frame + 1);
  last_progress = Node::Clock::now();
  auto healthText = [&] {
    std::ostringstream os;
    for (const auto& p : pipeline) {
      const auto it = health.find(p);
      const bool alive = sup.running(p);
      os << p << (alive ? "" : "(dead)");
      if (it != health.end()) {
        char buf[64];
        std::snprintf(buf, sizeof buf, " %.0fms", it->second.time_mean_ms);
        os << buf;
        const int64_t bad = it->second.decode_errors + it->second.timeouts + it->second.errors + it->second.frame_gaps;
        if (bad) os << " !" << bad;
      }
      os << "  ";
    }
    return os.str();
  };
  while (sup.running("player") || slot_last < last_frame) {
    if (signalReceived()) throw Failure("interrupted");
    failIfDead("player");
    failIfSilent();
    const double idle = std::chrono::duration<double>(Node::Clock::now() - last_progress).count();
    if (idle > stall_s) {
      std::string detail;
      for (const auto& p : pipeline) detail += "  " + p + ":\n" + sup.tail(p, 5);
      throw Failure("pipeline stalled: no SLOT_STATE for " + std::to_string(int(stall_s)) + " s after frame " +
                    std::to_string(slot_last) + "\n" + detail);
    }
    if (!sup.running("player") && idle > 10) break;  // the player is done; the tail is not coming
    node.spinUntil([] { return false; }, 0.1);
    if (!quiet) progress.update(slot_last + 1, healthText());
  }
  if (!quiet) progress.finish(healthText());
  failIfDead("player");
  // Every process must still be reporting before it is asked to stop: one whose heartbeat is late
  // may be stopped (SIGSTOP) or hung while the others solved its frames without it (a rate-mode
  // run ends all the same). Wait until it reports again or failIfSilent names it, rather than kill
  // it and call it "did not exit cleanly".
  for (bool late = true; late;) {
    late = false;
    for (const auto& p : pipeline)
      late = late || !heard.count(p) || std::chrono::duration<double>(Node::Clock::now() - heard[p]).count() > 2.5;
    if (!late) break;
    failIfDead("player");
    failIfSilent();
    node.spinUntil([] { return false; }, 0.1);
  }
  // A process may still hold frames it has not taken yet (end_wait.hpp).
  for (run::EndWait wait;;) {
    const FrameAccounting a = accountFrames(health, last_frame + 1, accounted);
    long long taken = 0;
    for (const ProcessFrames& p : a.processes) taken += p.handled + p.skipped;
    const double now_s = std::chrono::duration<double>(Node::Clock::now().time_since_epoch()).count();
    if (!wait.waiting(now_s, a.lost(), taken)) break;
    failIfDead("player");
    failIfSilent();
    node.spinUntil([] { return false; }, 0.1);
  }

  // 5. Stop in pipeline order so every process flushes (the renderer writes its summary, the
  // logger closes the log).
  // The launcher keeps reading while it waits, so each process's last PROCESS_STATUS is heard.
  const auto listen = [&] { node.spinUntil([] { return false; }, 0.02); };
  for (const std::string p : {"detector", "odometry", "tracker", "backend", "mapper", "renderer", "foxglove"}) {
    if ((p == std::string("renderer") && no_render) || (p == std::string("detector") && !geometric) ||
        (p == std::string("foxglove") && !foxglove) || (p == std::string("mapper") && no_map))
      continue;
    // The mapper finishes its keyframes and loop closure and writes the map files before it exits.
    const double grace = p == std::string("renderer") ? 60.0 : p == std::string("mapper") ? 120.0 : 10.0;
    const int code = sup.stop(p, grace, listen);
    if (code != 0) throw Failure(p + " did not exit cleanly (code " + std::to_string(code) + "):\n" + sup.tail(p));
  }
  // UDP datagrams the kernel dropped in this namespace during the run on sockets that do not
  // report their own (the logger's, the launcher's): published in the launcher's PROCESS_STATUS
  // (udp_drops_elsewhere) while the logger still records, so the terminal, report.md and
  // metrics.json add up the same counters.
  if (const int64_t after = udpReceiveBufferErrors(); after >= 0 && kernel_drops_before >= 0) {
    int64_t reported = 0;
    for (const auto& [name, st] : health) reported += statusCounter(st, "udp_drops");
    node.status().set("udp_drops_elsewhere", std::max<int64_t>(0, after - kernel_drops_before - reported));
  }
  node.publishStatus();
  health["launcher"] = node.status().toMessage();
  node.spinUntil([] { return false; }, 0.3);
  sup.stop("lcm-logger");
  // Where the two cores went: each process's CPU time over the whole run, per played frame.
  std::vector<std::pair<std::string, double>> cpu_ms;
  {
    std::string line;
    for (const std::string p : {"odometry", "detector", "tracker", "backend", "mapper", "renderer", "foxglove", "player",
                                "lcm-logger"}) {
      if ((p == std::string("renderer") && no_render) || (p == std::string("foxglove") && !foxglove) ||
          (p == std::string("detector") && !geometric) || (p == std::string("mapper") && no_map))
        continue;
      const double s = sup.cpuSeconds(p);
      if (s < 0) continue;
      cpu_ms.emplace_back(p, 1e3 * s / (last_frame + 1));
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s%s %.1f ms", line.empty() ? "" : ", ", p.c_str(), cpu_ms.back().second);
      line += buf;
    }
    std::fprintf(stderr, "CPU per frame: %s\n", line.c_str());
  }
  // The pipeline rate: from the player's start (less its start-up delay) to the last SLOT_STATE.
  const double play_s = std::chrono::duration<double>(last_slot_time - play_start).count() - 0.2;
  const double rate = play_s > 0 ? slot_frames / play_s : 0.0;
  std::fprintf(stderr, "SLOT_STATE for %d of %d frames; pipeline rate %.2f frames/s (%s)\n", slot_frames,
               last_frame + 1, rate, speed > 0 ? "rate mode" : "lockstep");
  writeSpeed(out + "/speed.yaml", cpu_ms, rate, load_before, loadAverage());
  if (slot_frames != last_frame + 1) std::cerr << "warning: frames are missing from SLOT_STATE\n";
  // Where every frame went, and the memory of each process over the run.
  const FrameAccounting accounting = accountFrames(health, last_frame + 1, accounted);
  std::cerr << accounting.table();
  std::cerr << "memory (RSS MB, start / middle / three quarters / end):\n";
  for (const auto& [p, samples] : rss)
    if (const auto r = summarizeRss(samples)) {
      char line[128];
      std::snprintf(line, sizeof line, "  %-10s %7.1f %7.1f %7.1f %7.1f\n", p.c_str(), r->start_mb, r->middle_mb,
                    r->three_quarters_mb, r->end_mb);
      std::cerr << line;
    }
  if (const auto refused = node.status().refusals(); !refused.empty()) {
    std::string what;
    int64_t total = 0;
    for (const auto& [key, n] : refused) {
      what += (total ? ", " : "") + key + " " + std::to_string(n);
      total += n;
    }
    std::fprintf(stderr, "launcher: refused %lld messages (%s)\n", static_cast<long long>(total), what.c_str());
  }

  // 6. Evaluate and export.
  if (!no_eval) {
    std::vector<std::string> eval = {bin + "/dlslot-eval", "--config", config, "--log", out + "/run.lcmlog",
                                     "--out", out, "--export", out};
    if (input.empty()) {
      eval.insert(eval.end(), {"--kitti", root, "--sequence", sequence});
      if (!no_map) eval.insert(eval.end(), {"--map", out});
    } else {  // ground truth from the run's log (the player's poses.txt), detections' calib for KITTI exports
      const std::string cam = player::readSensorCalibration(sensor_calib).camera_calib;
      if (!cam.empty()) eval.insert(eval.end(), {"--calib", cam});
    }
    if (runToEnd(sup, "eval", eval, logs + "/eval.log") != 0) throw Failure("dlslot-eval failed:\n" + sup.tail("eval", 30));
    std::cout << run::readText(logs + "/eval.log");
  }
  std::cout << "outputs in " << out << ": run.lcmlog, speed.yaml, trajectory_*.txt, tracks_kitti.txt, metrics.json, report.md, "
            << (no_render ? "" : "bev/, ") << (no_map ? "" : "map.pcd, map_removed.pcd, map.png, ")
            << "plots/, config.yaml, logs/\n";
  std::cout << "to look at it: report.md has every table; " << (no_render ? "" : "bev/ one bird's-eye image a frame "
            "(points, boxes coloured by track with id and speed, the trajectories; any image viewer), ")
            << (no_map ? "" : "map.png the static map from above, map.pcd in any point-cloud viewer, ")
            << "plots/ the trajectories and their errors, the objects' velocity errors by range and by track age\n";
  std::cout << std::flush;
  std::cerr << "dlslot-run: " << accounting.verdict() << "\n";
  if (accounting.hasLoss() && !allow_loss) return 4;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return runMain("dlslot-run", [&] {
    try {
      return runPipeline(argc, argv);
    } catch (const Failure& f) {
      std::cerr << "\ndlslot-run: FAILED: " << f.what() << "\n";
      return 3;
    }
  });
}
