// dlslot-compare: the paper's comparison on one sequence. Runs the four modes (A-LOAM, A-LOAM*,
// DL-SLOT, two-stage) with dlslot-run and prints Table I (ego accuracy per mode, plus tracking)
// and Table II (mean time per module per frame), saved as OUT/comparison.md.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include <thread>

#include "dlslot/node.hpp"
#include "supervisor.hpp"

using namespace dlslot;
namespace fs = std::filesystem;

namespace {

const std::vector<std::pair<std::string, std::string>> kModes = {
    {"aloam", "A-LOAM"}, {"aloam-filtered", "A-LOAM*"}, {"slot", "DL-SLOT"}, {"two-stage", "two-stage"}};

std::string cell(const YAML::Node& metrics, const std::string& key, const char* fmt) {
  const YAML::Node v = metrics[key];
  if (!v || v.IsNull()) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v.as<double>());
  return buf;
}

int compare(int argc, char** argv) {
  std::string root, sequence = "0000", scenario, config = "config/dlslot.yaml", out, lcm_url;
  std::vector<std::string> detections;
  int frames = -1, seed = 1;
  CommandLine cl("dlslot-compare", "Runs A-LOAM, A-LOAM*, DL-SLOT and two-stage on one sequence; prints Table I and II.");
  cl.option("--kitti", &root, "KITTI root");
  cl.option("--sequence", &sequence, "sequence (default 0000)");
  cl.repeated("--detections", &detections, "detection file or directory");
  cl.option("--scenario", &scenario, "simulate this scenario once, then compare on it");
  cl.option("--frames", &frames, "frames (simulated, or played)");
  cl.option("--seed", &seed, "simulator seed (default 1)");
  cl.option("--config", &config, "YAML config (default config/dlslot.yaml)");
  cl.option("--out", &out, "output directory (default out/compare-<scenario or sequence>)");
  cl.option("--lcm-url", &lcm_url, "LCM URL (default: $LCM_DEFAULT_URL)");
  if (!cl.parse(argc, argv)) return 0;
  if (root.empty() == scenario.empty()) throw std::invalid_argument("give either --kitti ROOT or --scenario NAME");
  config = fs::absolute(findConfigFile(config)).string();
  if (out.empty()) out = "out/compare-" + (scenario.empty() ? sequence : fs::path(scenario).stem().string());
  fs::create_directories(out);
  const std::string bin = fs::read_symlink("/proc/self/exe").parent_path().string();
  run::Supervisor sup;
  auto runToEnd = [&](const std::string& name, const std::vector<std::string>& args) {
    // Output passes through to the terminal (progress lines) and into the run's own logs.
    const pid_t pid = fork();
    if (pid == 0) {
      std::vector<char*> a;
      for (const auto& s : args) a.push_back(const_cast<char*>(s.c_str()));
      a.push_back(nullptr);
      execv(a[0], a.data());
      _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error(name + " failed");
  };

  if (!scenario.empty()) {
    root = out + "/data";
    std::vector<std::string> sim = {bin + "/dlslot-sim", "--scenario", scenario, "--out", root,
                                    "--seed", std::to_string(seed), "--sequence", sequence};
    if (frames > 0) sim.insert(sim.end(), {"--frames", std::to_string(frames)});
    runToEnd("dlslot-sim", sim);
    detections = {root + "/detections/sim"};
    frames = -1;
  }
  std::vector<YAML::Node> metrics;
  for (const auto& [mode, label] : kModes) {
    std::cerr << "== " << label << " (" << mode << ")\n";
    std::vector<std::string> a = {bin + "/dlslot-run", "--kitti", root, "--sequence", sequence, "--mode", mode,
                                  "--config", config, "--out", out + "/" + mode, "--no-render"};
    for (const auto& d : detections) a.insert(a.end(), {"--detections", d});
    if (frames > 0) a.insert(a.end(), {"--frames", std::to_string(frames)});
    if (!lcm_url.empty()) a.insert(a.end(), {"--lcm-url", lcm_url});
    runToEnd("dlslot-run --mode " + mode, a);
    metrics.push_back(YAML::LoadFile(out + "/" + mode + "/metrics.json"));
  }

  std::ostringstream md;
  md << "# Comparison on " << (scenario.empty() ? "KITTI " + root + " sequence " + sequence : "scenario " + scenario)
     << "\n\n## Table I: ego-motion and tracking accuracy\n\n"
     << "| mode | t_rel % (100-800 m) | r_rel deg/100m | t_rel % (10-80 m) | r_rel deg/100m (10-80 m) | ATE m | RPE1 m | "
        "RPE1 deg | MOTA | IDSW | velocity RMSE m/s |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (size_t i = 0; i < kModes.size(); ++i) {
    const YAML::Node& m = metrics[i];
    const bool estimatesObjects = kModes[i].first == "slot" || kModes[i].first == "two-stage";
    md << "| " << kModes[i].second << " | " << cell(m, "ego.t_rel_pct", "%.2f") << " | "
       << cell(m, "ego.r_rel_deg_per_100m", "%.3f") << " | " << cell(m, "ego.t_rel_short_pct", "%.2f") << " | "
       << cell(m, "ego.r_rel_short_deg_per_100m", "%.3f") << " | " << cell(m, "ego.ate_rmse_m", "%.3f") << " | "
       << cell(m, "ego.rpe1_t_m", "%.4f") << " | " << cell(m, "ego.rpe1_r_deg", "%.4f") << " | "
       << (estimatesObjects ? cell(m, "tracking.mota", "%.3f") + " | " + cell(m, "tracking.idsw", "%.0f") + " | " +
                                    cell(m, "tracking.velocity_rmse_mps", "%.3f")
                              : std::string("- | - | -"))
       << " |\n";
  }
  md << "\nA-LOAM and A-LOAM* run no object estimation, so their tracking columns are '-'.\n"
     << "\n## Table II: mean time per module per frame (ms)\n\n"
     << "| mode | odometry | trajectory association | optimization |\n|---|---|---|---|\n";
  for (size_t i = 0; i < kModes.size(); ++i) {
    const YAML::Node& m = metrics[i];
    md << "| " << kModes[i].second << " | " << cell(m, "timing_ms.odometry.mean", "%.1f") << " | "
       << cell(m, "timing_ms.tracker.mean", "%.2f") << " | " << cell(m, "timing_ms.backend.mean", "%.2f") << " |\n";
  }
  std::ofstream(out + "/comparison.md") << md.str();
  std::cout << md.str() << "\nsaved " << out << "/comparison.md\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-compare", [&] { return compare(argc, argv); }); }
