// dlslot-compare: the paper's comparison on one sequence. Runs the four modes (A-LOAM, A-LOAM*,
// DL-SLOT, two-stage) with dlslot-run and prints Table I (ego accuracy per mode, plus tracking)
// and Table II (mean time per module per frame), saved as OUT/comparison.md. With --seeds, the
// scenario is simulated and compared once per seed (OUT/seed-N/) and the mean and spread over the
// seeds per mode follow (OUT/seeds.md): one seed's numbers say little about a method.
#include <yaml-cpp/yaml.h>

#include <algorithm>
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

// "1,2,3" or "6-10" (or both: "1,3,6-10") -> the seeds.
std::vector<int> parseSeeds(const std::string& list) {
  std::vector<int> seeds;
  std::stringstream ss(list);
  std::string item;
  auto number = [&](const std::string& t) {
    size_t used = 0;
    int v = -1;
    try {
      v = std::stoi(t, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != t.size() || t.empty() || v < 0)
      throw std::invalid_argument("--seeds: expected non-negative integers like 1,2,3 or 6-10, got '" + list + "'");
    return v;
  };
  while (std::getline(ss, item, ',')) {
    const size_t dash = item.find('-');
    if (dash == std::string::npos) {
      seeds.push_back(number(item));
      continue;
    }
    const int lo = number(item.substr(0, dash)), hi = number(item.substr(dash + 1));
    if (hi < lo) throw std::invalid_argument("--seeds: range '" + item + "' runs backwards");
    for (int v = lo; v <= hi; ++v) seeds.push_back(v);
  }
  if (seeds.empty()) throw std::invalid_argument("--seeds: no seeds in '" + list + "'");
  return seeds;
}

// Mean, sample standard deviation, min and max of a metric over seeds ("-" when no seed has it).
std::string spread(const std::vector<YAML::Node>& per_seed, const std::string& key, const char* fmt) {
  std::vector<double> v;
  for (const YAML::Node& m : per_seed)
    if (m[key] && !m[key].IsNull()) v.push_back(m[key].as<double>());
  if (v.empty()) return "-";
  double mean = 0, var = 0;
  for (double x : v) mean += x;
  mean /= v.size();
  for (double x : v) var += (x - mean) * (x - mean);
  const double sd = v.size() > 1 ? std::sqrt(var / (v.size() - 1)) : 0.0;
  char a[32], b[32], lo[32], hi[32];
  std::snprintf(a, sizeof a, fmt, mean);
  std::snprintf(b, sizeof b, fmt, sd);
  std::snprintf(lo, sizeof lo, fmt, *std::min_element(v.begin(), v.end()));
  std::snprintf(hi, sizeof hi, fmt, *std::max_element(v.begin(), v.end()));
  return std::string(a) + " ± " + b + " [" + lo + ", " + hi + "]";
}

int compare(int argc, char** argv) {
  std::string root, sequence = "0000", scenario, config = "config/dlslot.yaml", out, lcm_url, detector;
  std::vector<std::string> detections;
  std::string seeds_arg;
  int frames = -1, seed = 1;
  CommandLine cl("dlslot-compare", "Runs A-LOAM, A-LOAM*, DL-SLOT and two-stage on one sequence; prints Table I and II.");
  cl.option("--kitti", &root, "KITTI root");
  cl.option("--sequence", &sequence, "sequence (default 0000)");
  cl.repeated("--detections", &detections, "detection file or directory");
  cl.option("--detector", &detector,
            "geometric | files: where every mode's DETECTIONS come from (as dlslot-run --detector; default: files "
            "when there are any, else geometric)");
  cl.option("--scenario", &scenario, "simulate this scenario once, then compare on it");
  cl.option("--frames", &frames, "frames (simulated, or played)");
  cl.option("--seed", &seed, "simulator seed (default 1)");
  cl.option("--seeds", &seeds_arg,
            "simulate and compare once per seed (e.g. 1,2,3 or 6-10), then print the mean and spread per mode; "
            "tune on seeds 1-5, report 6-10 as out of sample");
  cl.option("--config", &config, "YAML config (default config/dlslot.yaml)");
  cl.option("--out", &out, "output directory (default out/compare-<scenario or sequence>)");
  cl.option("--lcm-url", &lcm_url, "LCM URL (default: $LCM_DEFAULT_URL)");
  if (!cl.parse(argc, argv)) return 0;
  if (root.empty() == scenario.empty()) throw std::invalid_argument("give either --kitti ROOT or --scenario NAME");
  config = fs::absolute(findConfigFile(config)).string();
  if (out.empty()) out = "out/compare-" + (scenario.empty() ? sequence : fs::path(scenario).stem().string());
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

  // One comparison: simulate (a scenario) into OUT/data, run the four modes, write OUT/comparison.md.
  auto compareOnce = [&](int seed, const std::string& out, std::string root, std::vector<std::string> detections,
                         int frames) {
    fs::create_directories(out);
    if (!scenario.empty()) {
      root = out + "/data";
      std::vector<std::string> sim = {bin + "/dlslot-sim", "--scenario", scenario, "--out", root,
                                      "--seed", std::to_string(seed), "--sequence", sequence};
      if (frames > 0) sim.insert(sim.end(), {"--frames", std::to_string(frames)});
      runToEnd("dlslot-sim", sim);
      if (detector != "geometric") detections = {root + "/detections/sim"};
      frames = -1;
    }
    std::vector<YAML::Node> metrics;
    for (const auto& [mode, label] : kModes) {
      std::cerr << "== " << label << " (" << mode << ")\n";
      std::vector<std::string> a = {bin + "/dlslot-run", "--kitti", root, "--sequence", sequence, "--mode", mode,
                                    "--config", config, "--out", out + "/" + mode, "--no-render"};
      for (const auto& d : detections) a.insert(a.end(), {"--detections", d});
      if (!detector.empty()) a.insert(a.end(), {"--detector", detector});
      if (frames > 0) a.insert(a.end(), {"--frames", std::to_string(frames)});
      if (!lcm_url.empty()) a.insert(a.end(), {"--lcm-url", lcm_url});
      runToEnd("dlslot-run --mode " + mode, a);
      metrics.push_back(YAML::LoadFile(out + "/" + mode + "/metrics.json"));
    }

    std::ostringstream md;
    md << "# Comparison on " << (scenario.empty() ? "KITTI " + root + " sequence " + sequence : "scenario " + scenario)
       << "\n\nDetections: "
       << (detector == "geometric" || (detector.empty() && detections.empty()) ? "dlslot-detector (geometric)"
                                                                               : "files")
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
    return metrics;
  };

  if (seeds_arg.empty()) {
    compareOnce(seed, out, root, detections, frames);
    return 0;
  }
  if (scenario.empty()) throw std::invalid_argument("--seeds needs --scenario (seeds are the simulator's)");
  const std::vector<int> seeds = parseSeeds(seeds_arg);
  std::vector<std::vector<YAML::Node>> by_mode(kModes.size());
  for (int s : seeds) {
    std::cerr << "==== seed " << s << "\n";
    const std::vector<YAML::Node> metrics =
        compareOnce(s, out + "/seed-" + std::to_string(s), root, detections, frames);
    for (size_t i = 0; i < kModes.size(); ++i) by_mode[i].push_back(metrics[i]);
  }
  std::ostringstream md;
  md << "# Comparison on scenario " << scenario << ", seeds " << seeds_arg << " (" << seeds.size()
     << " runs)\n\nmean ± sample standard deviation [min, max] over the seeds; each seed's tables in "
     << out << "/seed-N/comparison.md\n\n"
     << "| mode | ATE m | t_rel % (100-800 m) | t_rel % (10-80 m) | velocity RMSE m/s | MOTA |\n|---|---|---|---|---|---|\n";
  for (size_t i = 0; i < kModes.size(); ++i) {
    const bool estimatesObjects = kModes[i].first == "slot" || kModes[i].first == "two-stage";
    md << "| " << kModes[i].second << " | " << spread(by_mode[i], "ego.ate_rmse_m", "%.3f") << " | "
       << spread(by_mode[i], "ego.t_rel_pct", "%.2f") << " | " << spread(by_mode[i], "ego.t_rel_short_pct", "%.2f")
       << " | "
       << (estimatesObjects ? spread(by_mode[i], "tracking.velocity_rmse_mps", "%.3f") + " | " +
                                  spread(by_mode[i], "tracking.mota", "%.3f")
                            : std::string("- | -"))
       << " |\n";
  }
  md << "\nPer seed (ATE m / t_rel %):\n\n| seed |";
  for (const auto& mode : kModes) md << " " << mode.second << " |";
  md << "\n|---|";
  for (size_t i = 0; i < kModes.size(); ++i) md << "---|";
  md << "\n";
  for (size_t k = 0; k < seeds.size(); ++k) {
    md << "| " << seeds[k] << " |";
    for (size_t i = 0; i < kModes.size(); ++i)
      md << " " << cell(by_mode[i][k], "ego.ate_rmse_m", "%.3f") << " / " << cell(by_mode[i][k], "ego.t_rel_pct", "%.2f")
         << " |";
    md << "\n";
  }
  std::ofstream(out + "/seeds.md") << md.str();
  std::cout << "\n" << md.str() << "\nsaved " << out << "/seeds.md\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-compare", [&] { return compare(argc, argv); }); }
