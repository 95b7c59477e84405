// dlslot-track-eval (./dlslot track-eval): the tracker alone over many KITTI tracking sequences
// from detection files (no scans needed), scored with the KITTI protocol (kitti_protocol.hpp):
// one per-class table per sequence and over all of them, and OUT/metrics.json with the flat keys
// tracking.<class>.<k> (all sequences pooled, as AB3DMOT computes sAMOTA) and
// sequences.<SSSS>.<class>.<k>.
//
// Two runs, because the two kinds of metric ask for two outputs:
// - the default output (confirmed tracks, the config's score thresholds), OUT/data/SSSS.txt:
//   MOTA, MOTP, IDSW, FRAG, FP, FN, HOTA: what a user of the tracker gets;
// - every track of every detection (output all, no score threshold), each row with its track's
//   confidence, OUT/data_all/SSSS.txt: sAMOTA and AMOTA, which sweep their own thresholds over
//   the confidences (a threshold set beforehand would cut their recall axis short).
#include <chrono>
#include <cmath>
#include <cstring>
#include <random>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "dlslot/kitti.hpp"
#include "dlslot/node.hpp"
#include "dlslot/progress.hpp"
#include "kitti_protocol.hpp"
#include "metrics_report.hpp"
#include "offline_run.hpp"
#include "tracker_config.hpp"

using namespace dlslot;
using namespace dlslot::eval;
namespace fs = std::filesystem;

namespace {

// Every sequence with a label file under ROOT/training/label_02 (or ROOT/label_02).
std::vector<std::string> sequencesIn(const std::string& root) {
  fs::path labels = fs::path(root) / "training" / "label_02";
  if (!fs::is_directory(labels)) labels = fs::path(root) / "label_02";
  if (!fs::is_directory(labels))
    throw std::invalid_argument(root + ": no training/label_02/ to list sequences from; give --sequences");
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(labels))
    if (e.path().extension() == ".txt") out.push_back(e.path().stem().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::string cell(const std::optional<double>& v, const char* fmt = "%.3f") {
  if (!v) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, fmt, *v);
  return buf;
}

// One table row per class: the numbers the issue names first.
void printRows(std::ostream& out, const std::string& what, const std::map<std::string, KittiClassMetrics>& m) {
  for (const auto& [cls, k] : m) {
    char line[256];
    std::snprintf(line, sizeof line, "| %-7s | %-10s | %6d | %6s | %6s | %6s | %5d | %5d | %6d | %6d | %6s |\n",
                  what.c_str(), cls.c_str(), k.all.labels, cell(k.all.mota).c_str(), cell(k.sweep.samota).c_str(),
                  cell(k.sweep.amota).c_str(), k.all.idsw, k.all.frag, k.all.fp, k.all.fn,
                  cell(k.hota ? std::optional<double>(k.hota->hota) : std::nullopt).c_str());
    out << line;
  }
}

// The default output's counts with the all-tracks output's score sweep (sAMOTA, AMOTA).
std::map<std::string, KittiClassMetrics> combine(std::map<std::string, KittiClassMetrics> output,
                                                 const std::map<std::string, KittiClassMetrics>& sweep) {
  for (auto& [cls, k] : output)
    if (const auto s = sweep.find(cls); s != sweep.end()) {
      k.sweep = s->second.sweep;
      k.sweep_ab3dmot = s->second.sweep_ab3dmot;
      k.best_switches = s->second.best_switches;
    }
  return output;
}

// Each ego pose moved by an independent error of GPS/INS grade: translation N(0, sigma_m) along x
// and y and a yaw N(0, sigma_deg) about the sensor, frame by frame (the jitter KITTI's GPS/INS
// poses show from frame to frame, not a drift). Seeded: the same perturbation every run.
std::vector<Pose> perturbed(std::vector<Pose> poses, double sigma_m, double sigma_deg, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (Pose& X : poses) {
    Pose d = Pose::Identity();
    d.linear() = Eigen::AngleAxisd(sigma_deg * M_PI / 180.0 * n(rng), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    d.translation() << sigma_m * n(rng), sigma_m * n(rng), 0.0;
    X = X * d;
  }
  return poses;
}

// Each ego pose moved by a random walk: translation steps N(0, step_m) along x and y, summed frame
// by frame (a slow drift of the GPS/INS solution, as parked cars spread up to ~2 m in the world
// frame over a KITTI sequence). Seeded.
std::vector<Pose> drifted(std::vector<Pose> poses, double step_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, step_m);
  Eigen::Vector3d drift = Eigen::Vector3d::Zero();
  for (Pose& X : poses) {
    drift += Eigen::Vector3d(n(rng), n(rng), 0.0);
    X.translation() += drift;
  }
  return poses;
}

// Every detection as a track of its own: what the detections alone can recall (the ceiling no
// tracker that reports detected boxes can pass).
std::vector<kitti::LabelRow> detectionRows(const kitti::SequenceReader& reader) {
  std::vector<kitti::LabelRow> rows;
  int id = 0;
  for (int i = 0; i < reader.size(); ++i) {
    const Frame frame = reader.read(i);
    for (Box b : frame.detections) {
      b.id = id++;
      if (auto r = kitti::resultRow(frame.index, b, reader.calib())) rows.push_back(std::move(*r));
    }
  }
  return rows;
}

double recallOf(const KittiCounts& c) { return c.labels > 0 ? 1.0 - static_cast<double>(c.fn) / c.labels : 0.0; }

int run(int argc, char** argv) {
  std::string root, poses, sequences_arg, out, config = kDefaultConfig, output, pose_noise, ab3dmot;
  double pose_drift = 0;
  std::vector<std::string> detections;
  double min_iou = 0.25, frame_period = 0.1;
  bool quiet = false;
  CommandLine cl("dlslot-track-eval",
                 "Runs the tracker over KITTI tracking sequences from detection files (no scans needed) and scores "
                 "the results with the KITTI protocol, per class, per sequence and over all.");
  cl.option("--kitti", &root, "KITTI tracking root (training/label_02, training/calib)");
  cl.repeated("--detections", &detections, "detection directory holding SSSS.txt (repeat: one per class file)");
  cl.option("--poses", &poses, "directory of SSSS.txt ego poses (KITTI 3x4, lidar frame); default: the "
                               "sequence's own, else identity");
  cl.option("--sequences", &sequences_arg, "comma-separated sequences (default: every labelled one in ROOT)");
  cl.option("--out", &out, "output directory: data/SSSS.txt results files, metrics.json, report.md");
  cl.option("--config", &config, "YAML config, section tracker (default config/dlslot.yaml)");
  cl.option("--output", &output, "confirmed | all (default: tracker.output of the config)");
  cl.option("--min-iou", &min_iou, "3-D IoU gate of the KITTI protocol (default 0.25, AB3DMOT's)");
  cl.option("--frame-period", &frame_period, "seconds per frame (default 0.1)");
  cl.option("--pose-noise", &pose_noise, "M,DEG: perturb every ego pose by N(0, M) metres in x and y and N(0, DEG) "
                                         "degrees of yaw, independently per frame (a robustness test; seeded)");
  cl.option("--pose-drift", &pose_drift, "M: add a random walk of N(0, M) metres a frame in x and y to the ego poses "
                                         "(a slow drift of the solution; a robustness test; seeded)");
  cl.option("--ab3dmot-eval", &ab3dmot, "a checkout of xinshuoweng/AB3DMOT: also score OUT/data_all with its own "
                                        "scripts/KITTI/evaluate.py (scripts/ab3dmot-eval; several minutes) and "
                                        "print its numbers beside ours");
  cl.flag("--quiet", &quiet, "no progress line");
  if (!cl.parse(argc, argv)) return 0;
  if (root.empty() || detections.empty() || out.empty())
    throw std::invalid_argument("--kitti ROOT, --detections DIR and --out DIR are required\n" + cl.usage());

  Channels channels;
  ConfigSection cfg_root = loadPipelineConfig(config, channels);
  tracker::TrackerConfig cfg = tracker::TrackerConfig::read(cfg_root.section("tracker"));
  if (!output.empty()) cfg.output = tracker::trackOutputFromName(output);
  const std::vector<std::string> sequences = sequences_arg.empty() ? sequencesIn(root) : splitList(sequences_arg);
  tracker::TrackerConfig sweep_cfg = cfg;
  sweep_cfg.output = tracker::TrackOutput::All;
  for (ClassPolicy& p : sweep_cfg.associator.classes) p.min_score = p.min_score_to_extend = -1e300;
  double noise_m = 0, noise_deg = 0;
  if (!pose_noise.empty()) {
    const std::vector<std::string> v = splitList(pose_noise);
    char* end = nullptr;
    if (v.size() == 2) noise_m = std::strtod(v[0].c_str(), &end);
    if (v.size() != 2 || *end || !(noise_m >= 0) || !(std::strtod(v[1].c_str(), &end) >= 0) || *end)
      throw std::invalid_argument("--pose-noise: expected M,DEG (two numbers >= 0), got '" + pose_noise + "'");
    noise_deg = std::strtod(v[1].c_str(), nullptr);
  }
  if (!(pose_drift >= 0) || !std::isfinite(pose_drift))
    throw std::invalid_argument("--pose-drift: expected metres >= 0, got " + std::to_string(pose_drift));
  if (!ab3dmot.empty() && !fs::exists(fs::path(ab3dmot) / "scripts" / "KITTI" / "evaluate.py"))
    throw std::invalid_argument("--ab3dmot-eval " + ab3dmot +
                                ": no scripts/KITTI/evaluate.py there (expected a checkout of xinshuoweng/AB3DMOT)");
  fs::create_directories(fs::path(out) / "data");
  fs::create_directories(fs::path(out) / "data_all");

  // Score the classes the detection files hold (a class without detections would only score its
  // labels as misses): those of the rows of the all-tracks run, which tracks every detection.
  KittiProtocolOptions options;
  options.min_iou = min_iou;
  std::set<std::string> detected;
  std::vector<KittiSequence> all, all_sweep, all_detections;
  std::map<std::string, std::map<std::string, KittiClassMetrics>> per_sequence;
  std::vector<std::string> notes;
  TimingStats association_ms;
  tracker::ClassDecisions decisions;  // of the all-tracks run, over every sequence
  int suppressed_rows = 0;
  ProgressLine progress("track-eval", static_cast<int>(sequences.size()));
  for (size_t i = 0; i < sequences.size(); ++i) {
    const std::string& s = sequences[i];
    if (!quiet) progress.update(static_cast<int>(i), "sequence " + s);
    const kitti::SequenceReader reader(root, s, detections, -1e300, frame_period);
    if (reader.paths().labels.empty()) throw std::invalid_argument(root + ": sequence " + s + " has no label file");
    std::string pose_source;
    std::vector<Pose> ego = tracker::egoPosesFor(reader, s, poses, &pose_source);
    // Only poses there are: a sequence tracked in the sensor frame has no pose error to simulate.
    if (!pose_noise.empty() && pose_source.rfind("no ego poses", 0) != 0) {
      ego = perturbed(std::move(ego), noise_m, noise_deg, 1000 + static_cast<unsigned>(i));
      pose_source += " perturbed by " + pose_noise;
    }
    if (pose_drift > 0 && pose_source.rfind("no ego poses", 0) != 0) {
      ego = drifted(std::move(ego), pose_drift, 2000 + static_cast<unsigned>(i));
      pose_source += " drifting by " + std::to_string(pose_drift) + " m a frame";
    }
    const tracker::OfflineResult r = tracker::associateSequence(reader, ego, cfg.associator, cfg.output);
    for (double ms : r.association_ms.samples()) association_ms.add(ms);
    kitti::writeTrackingLabels((fs::path(out) / "data" / (s + ".txt")).string(), r.tracks);
    char note[512];
    std::snprintf(note, sizeof note,
                  "%s: %d frames%s; %s; %d detections, %d not tracked (type %d, score %d, duplicate %d), %zu rows written, "
                  "%d outside the image",
                  s.c_str(), reader.size(), reader.hasScans() ? "" : " (no scans)", pose_source.c_str(), r.detections,
                  r.skipped.total(), r.skipped.untracked_type, r.skipped.below_score, r.skipped.duplicate,
                  r.tracks.size(), r.outside_image);
    KittiSequence seq{s, kitti::readTrackingLabels(reader.paths().labels), r.tracks, {}};
    for (int f = 0; f < reader.size(); ++f) seq.frames.push_back(f);
    const tracker::OfflineResult r_all = tracker::associateSequence(reader, ego, sweep_cfg.associator, sweep_cfg.output);
    // The class decisions of the window (ClassPlausibility), by reason, in the all-tracks run.
    const tracker::ClassDecisions& c = r_all.class_decisions;
    decisions += c;
    suppressed_rows += r_all.suppressed_rows;
    std::snprintf(note + std::strlen(note), sizeof note - std::strlen(note),
                  "; tracks re-labelled too fast %d, suppressed too fast %d, suppressed on another class %d (%d rows)",
                  c.relabelled_too_fast, c.suppressed_too_fast, c.suppressed_on_other_class, r_all.suppressed_rows);
    notes.push_back(note);
    kitti::writeTrackingLabels((fs::path(out) / "data_all" / (s + ".txt")).string(), r_all.tracks);
    KittiSequence seq_all{s, seq.labels, r_all.tracks, seq.frames};
    for (const kitti::LabelRow& row : r_all.tracks)
      if (const ClassPolicy* p = policyFor(cfg.associator.classes, row.type)) detected.insert(p->name);
    options.classes.assign(detected.begin(), detected.end());
    per_sequence[s] = combine(evaluateKittiTracking({seq}, options), evaluateKittiTracking({seq_all}, options));
    all_detections.push_back({s, seq.labels, detectionRows(reader), seq.frames});
    all.push_back(std::move(seq));
    all_sweep.push_back(std::move(seq_all));
  }
  if (!quiet) progress.finish();
  const std::map<std::string, KittiClassMetrics> overall_sweep = evaluateKittiTracking(all_sweep, options);
  const std::map<std::string, KittiClassMetrics> overall = combine(evaluateKittiTracking(all, options), overall_sweep);
  const std::map<std::string, KittiClassMetrics> ceiling = evaluateKittiTracking(all_detections, options);

  // The numbers AB3DMOT's evaluate.py reports for data_all/ (sAMOTA, AMOTA, and MOTA, IDSW, FP, FN
  // at its best single threshold), the recall there and with every track, and what the
  // detections alone recall.
  std::ostringstream headline;
  headline << "data_all/ as AB3DMOT's evaluate.py scores it (MOTA, IDSW, FP, FN, recall at the best single threshold); "
              "recall of every track; recall of the detections alone (each its own track):\n"
           << "| class      | sAMOTA |  AMOTA |   MOTA |  IDSW |     FP |     FN | recall | every track | detections |\n"
           << "|------------|--------|--------|--------|-------|--------|--------|--------|-------------|------------|\n";
  for (const auto& [cls, k] : overall_sweep) {
    const KittiCounts& b = k.sweep.best;
    const auto d = ceiling.find(cls);
    char line[256];
    std::snprintf(line, sizeof line, "| %-10s | %6s | %6s | %6s | %5d | %6d | %6d | %6.3f | %11.3f | %10s |\n", cls.c_str(),
                  cell(k.sweep.samota).c_str(), cell(k.sweep.amota).c_str(), cell(b.mota).c_str(), b.idsw, b.fp, b.fn,
                  recallOf(b), recallOf(k.all),
                  d == ceiling.end() ? "-" : cell(recallOf(d->second.all)).c_str());
    headline << line;
  }

  std::ostringstream table;
  table << "| seq     | class      | labels |   MOTA | sAMOTA |  AMOTA |  IDSW |  FRAG |     FP |     FN |   HOTA |\n"
        << "|---------|------------|--------|--------|--------|--------|-------|-------|--------|--------|--------|\n";
  for (const auto& [s, m] : per_sequence) printRows(table, s, m);
  printRows(table, "all", overall);

  // metrics.json: the pooled numbers under tracking.<class>, each sequence under sequences.<SSSS>.
  std::vector<std::pair<std::string, std::optional<double>>> kv;
  for (const auto& [cls, k] : overall)
    for (const auto& [key, v] : kittiValues(k)) kv.emplace_back("tracking." + cls + "." + key, v);
  for (const auto& [s, m] : per_sequence)
    for (const auto& [cls, k] : m)
      for (const auto& [key, v] : kittiValues(k)) kv.emplace_back("sequences." + s + "." + cls + "." + key, v);
  for (const auto& [cls, k] : overall_sweep) {
    kv.emplace_back("tracking." + cls + ".best_recall", recallOf(k.sweep.best));
    kv.emplace_back("tracking." + cls + ".recall_every_track", recallOf(k.all));
    if (const auto d = ceiling.find(cls); d != ceiling.end())
      kv.emplace_back("tracking." + cls + ".recall_detections", recallOf(d->second.all));
  }
  // The window's class decisions by reason (the all-tracks run, every sequence).
  kv.emplace_back("class_decisions.relabelled_too_fast", decisions.relabelled_too_fast);
  kv.emplace_back("class_decisions.suppressed_too_fast", decisions.suppressed_too_fast);
  kv.emplace_back("class_decisions.suppressed_on_other_class", decisions.suppressed_on_other_class);
  kv.emplace_back("class_decisions.suppressed_rows", suppressed_rows);
  kv.emplace_back("timing_ms.association.mean", association_ms.mean());
  kv.emplace_back("timing_ms.association.p95", association_ms.percentile(95));
  std::ofstream json(fs::path(out) / "metrics.json");
  json << "{\n";
  for (size_t i = 0; i < kv.size(); ++i)
    json << "  \"" << kv[i].first << "\": " << (kv[i].second ? cell(kv[i].second, "%.9g") : "null")
         << (i + 1 < kv.size() ? ",\n" : "\n");
  json << "}\n";

  // Where identities switch at the best threshold of the all-tracks output (what the score sweep
  // reports as IDSW), for finding their causes.
  std::ofstream switches(fs::path(out) / "switches.txt");
  switches << "# class sequence frame label_id from_track to_track (data_all/, at the best single threshold)\n";
  for (const auto& [cls, k] : overall)
    for (const IdSwitch& w : k.best_switches)
      switches << cls << " " << w.sequence << " " << w.frame << " " << w.label_id << " " << w.from << " " << w.to << "\n";

  std::ofstream report(fs::path(out) / "report.md");
  const char* what =
      "MOTA, IDSW, FRAG, FP, FN, HOTA: the default output (confirmed tracks, the config's score thresholds), data/. "
      "sAMOTA, AMOTA: every track of every detection with its confidence (output all, no threshold), data_all/, "
      "swept over 40 recall points.";
  report << "# Tracking on detections, KITTI protocol (3-D IoU >= " << min_iou << ")\n\n" << table.str() << "\n"
         << what << "\n\n";
  for (const std::string& n : notes) report << "- " << n << "\n";
  report << "\n" << headline.str();
  report.close();
  std::cout << table.str() << what << "\n\n" << headline.str();
  for (const std::string& n : notes) std::cerr << n << "\n";
  std::printf("association %.3f ms mean, %.3f ms p95 a frame; results in %s/data, metrics in %s/metrics.json\n",
              association_ms.mean(), association_ms.percentile(95), out.c_str(), out.c_str());
  if (!ab3dmot.empty()) {
    // AB3DMOT's own script on data_all/, one class at a time (scripts/ab3dmot-eval prints one line
    // a class), beside the same numbers from the protocol above.
    std::string seqs;
    for (const std::string& s : sequences) seqs += (seqs.empty() ? "" : ",") + s;
    std::string classes;
    for (const auto& [cls, k] : overall_sweep) classes += (classes.empty() ? "" : ",") + cls;
    const std::string cmd = "'" + (fs::path(DLSLOT_SOURCE_DIR) / "scripts" / "ab3dmot-eval").string() + "' '" + ab3dmot +
                            "' '" + (fs::path(out) / "data_all").string() + "' '" + root + "' --sequences " + seqs +
                            " --classes " + classes + " --work '" + (fs::path(out) / "ab3dmot").string() + "'";
    std::cerr << "running AB3DMOT's evaluate.py: " << cmd << "\n";
    std::FILE* p = popen(cmd.c_str(), "r");
    if (!p) throw std::runtime_error("cannot run " + cmd);
    std::map<std::string, std::map<std::string, double>> script;
    char buf[1024];
    while (std::fgets(buf, sizeof buf, p)) {
      std::cerr << buf;
      std::istringstream line(buf);
      std::string tag, cls, kvp;
      if (!(line >> tag >> cls) || tag != "ab3dmot-eval") continue;
      while (line >> kvp)
        if (const auto eq = kvp.find('='); eq != std::string::npos) script[cls][kvp.substr(0, eq)] = std::atof(kvp.c_str() + eq + 1);
    }
    if (const int rc = pclose(p); rc != 0) throw std::runtime_error("scripts/ab3dmot-eval failed (status " + std::to_string(rc) + ")");
    std::ostringstream cmp;
    cmp << "\nAB3DMOT's evaluate.py on data_all/ beside dlslot-eval's KITTI protocol on the same files:\n"
        << "| class      | sAMOTA script | sAMOTA ours | MOTA script | MOTA ours | IDSW script | IDSW ours |\n"
        << "|------------|---------------|-------------|-------------|-----------|-------------|-----------|\n";
    for (const auto& [cls, k] : overall_sweep) {
      const auto it = script.find(cls);
      if (it == script.end()) continue;
      auto get = [&](const char* key) { return it->second.count(key) ? it->second.at(key) : std::nan(""); };
      char line[256];
      std::snprintf(line, sizeof line, "| %-10s | %13.4f | %11.4f | %11.4f | %9.4f | %11.0f | %9d |\n", cls.c_str(),
                    get("samota"), k.sweep.samota.value_or(std::nan("")), get("mota"), k.sweep.best.mota.value_or(std::nan("")),
                    get("idsw"), k.sweep.best.idsw);
      cmp << line;
    }
    std::cout << cmp.str();
    std::ofstream(fs::path(out) / "report.md", std::ios::app) << cmp.str();
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-track-eval", [&] { return run(argc, argv); }); }
