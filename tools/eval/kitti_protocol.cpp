#include "kitti_protocol.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "assignment.hpp"
#include "box_overlap.hpp"

namespace dlslot::eval {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The neighbour class of the devkit: counted neither as a hit nor as a miss.
std::string neighbourOf(const std::string& cls) {
  if (cls == "car") return "van";
  if (cls == "pedestrian") return "person_sitting";
  return "";
}

// The camera frame (x right, y down, z forward) turned into a z-up frame by the rotation
// (x, y, z) -> (x, z, -y): a rigid map, so the 3-D IoU is that of the devkit's camera-frame boxes
// (footprint in the x-z plane, height along y), computed by box_overlap's iou3d.
Box upright(const kitti::CameraBox& c) {
  Box b;
  b.center = Eigen::Vector3d(c.bottom_center.x(), c.bottom_center.z(), -c.bottom_center.y() + 0.5 * c.h);
  b.size = Eigen::Vector3d(c.l, c.w, c.h);
  b.yaw = -c.rotation_y;
  return b;
}

// The devkit's boxoverlap(track, dontcare, "a"): the intersection over the track's own 2-D box.
double overlapOfTrack(const Eigen::Vector4d& t, const Eigen::Vector4d& d) {
  const double w = std::min(t[2], d[2]) - std::max(t[0], d[0]);
  const double h = std::min(t[3], d[3]) - std::max(t[1], d[1]);
  if (w <= 0 || h <= 0) return 0.0;
  return w * h / ((t[2] - t[0]) * (t[3] - t[1]));
}

struct Label {
  int id = -1;
  bool ignored = false;
};
struct Track {
  int id = -1;
  int key = 0;             // index of the track in SequenceFrames::score
  bool ignorable = false;  // ignored when unmatched: neighbour class, small, or in a DontCare region
};
struct FramePairs {
  int frame = 0;
  std::vector<Label> labels;
  std::vector<Track> tracks;
  std::vector<Box> label_boxes, track_boxes;  // upright(), for HOTA
  Eigen::MatrixXd iou;                        // labels x tracks
};
struct SequenceFrames {
  std::string name;
  std::vector<FramePairs> frames;
  // Per track: its rows in the sequence and its score, the mean of its rows' scores. AB3DMOT's
  // script overwrites every row's score with that mean at each pass and averages again at the next,
  // so the mean drifts by rounding from pass to pass, and a track whose mean is the threshold itself
  // is sometimes dropped. reaverage() repeats exactly that, so that sAMOTA is the script's to the digit.
  std::vector<int> rows;
  std::vector<double> score;

  void reaverage() {
    for (size_t k = 0; k < score.size(); ++k) {
      double sum = 0;
      for (int i = 0; i < rows[k]; ++i) sum += score[k];
      score[k] = sum / rows[k];
    }
  }
};

std::vector<int> framesOf(const KittiSequence& s) {
  if (!s.frames.empty()) return s.frames;
  int last = -1;
  for (const auto* rows : {&s.labels, &s.tracks})
    for (const kitti::LabelRow& r : *rows) last = std::max(last, r.frame);
  std::vector<int> frames(last + 1);
  for (int i = 0; i <= last; ++i) frames[i] = i;
  return frames;
}

// Everything about one class in one sequence that does not depend on the score threshold.
SequenceFrames prepare(const KittiSequence& s, const std::string& cls, const KittiProtocolOptions& o) {
  const std::string neighbour = neighbourOf(cls);
  const auto takesPart = [&](const std::string& type) {
    const std::string t = lower(type);
    return t == cls || (!neighbour.empty() && t == neighbour);
  };
  const std::vector<int> frames = framesOf(s);
  std::map<int, int> slot;  // frame -> index in `frames`
  for (size_t i = 0; i < frames.size(); ++i) slot[frames[i]] = static_cast<int>(i);
  const auto slotOf = [&](int frame) {
    const auto it = slot.find(frame);
    return it == slot.end() ? -1 : it->second;
  };

  // Rows by frame, in file order within a frame (the order the devkit sums scores in).
  std::vector<std::vector<const kitti::LabelRow*>> labels(frames.size()), dontcare(frames.size()), tracks(frames.size());
  for (const kitti::LabelRow& r : s.labels) {
    const int k = slotOf(r.frame);
    if (k < 0) continue;
    if (lower(r.type) == "dontcare")
      dontcare[k].push_back(&r);
    else if (takesPart(r.type) && r.track_id != -1)
      labels[k].push_back(&r);
  }
  for (const kitti::LabelRow& r : s.tracks) {
    const int k = slotOf(r.frame);
    if (k >= 0 && takesPart(r.type) && r.track_id != -1) tracks[k].push_back(&r);
  }

  SequenceFrames out;
  std::map<int, int> key_of;  // track id -> index in out.score
  std::vector<double> score_sum;
  for (size_t k = 0; k < frames.size(); ++k) {
    std::set<int> ids;
    for (const kitti::LabelRow* r : tracks[k]) {
      if (!ids.insert(r->track_id).second)
        throw std::invalid_argument("sequence " + s.name + ", frame " + std::to_string(frames[k]) + ": track id " +
                                    std::to_string(r->track_id) + " appears twice among the " + cls +
                                    " results (the KITTI devkit refuses such files)");
      const auto [it, is_new] = key_of.emplace(r->track_id, static_cast<int>(key_of.size()));
      if (is_new) {
        score_sum.push_back(0);
        out.rows.push_back(0);
      }
      score_sum[it->second] += r->score.value_or(-1.0);
      ++out.rows[it->second];
    }
  }
  for (size_t k = 0; k < score_sum.size(); ++k) out.score.push_back(score_sum[k] / out.rows[k]);

  out.name = s.name;
  out.frames.resize(frames.size());
  for (size_t k = 0; k < frames.size(); ++k) {
    FramePairs& f = out.frames[k];
    f.frame = frames[k];
    for (const kitti::LabelRow* r : labels[k]) {
      // The devkit reads truncation as int(float(...)).
      const int truncation = static_cast<int>(r->truncated);
      f.labels.push_back({r->track_id, truncation > o.max_truncation || r->occluded > o.max_occlusion ||
                                           lower(r->type) == neighbour});
      f.label_boxes.push_back(upright(r->box));
    }
    for (const kitti::LabelRow* r : tracks[k]) {
      const Eigen::Vector4d& b = r->bbox2d;
      const bool small = std::abs(b[1] - b[3]) <= o.min_height_px;
      const bool in_dontcare = std::any_of(dontcare[k].begin(), dontcare[k].end(),
                                           [&](const kitti::LabelRow* d) { return overlapOfTrack(b, d->bbox2d) > 0.5; });
      f.tracks.push_back({r->track_id, key_of.at(r->track_id), lower(r->type) == neighbour || small || in_dontcare});
      f.track_boxes.push_back(upright(r->box));
    }
    f.iou.resize(f.labels.size(), f.tracks.size());
    for (size_t i = 0; i < f.labels.size(); ++i)
      for (size_t j = 0; j < f.tracks.size(); ++j) f.iou(i, j) = iou3d(f.label_boxes[i], f.track_boxes[j]);
  }
  return out;
}

// A label's matched track id per frame it appears in (-1: missed), and whether it was ignored there.
struct LabelRun {
  std::vector<int> ids;
  std::vector<bool> ignored;
  std::vector<int> frames;  // the frame of each entry
};

// IDSW and FRAG of one label as the devkit counts them (its loop over gt trajectories, verbatim in
// behaviour: `last` forgets the id over ignored frames, a switch needs the previous frame matched).
// Each switch is appended to `switches` when given.
void countSwitches(const LabelRun& run, int& idsw, int& frag, const std::string& sequence, int label_id,
                   std::vector<IdSwitch>* switches) {
  const std::vector<int>& g = run.ids;
  const std::vector<bool>& ign = run.ignored;
  const size_t n = g.size();
  if (std::all_of(ign.begin(), ign.end(), [](bool b) { return b; })) return;
  if (std::all_of(g.begin(), g.end(), [](int id) { return id == -1; })) return;
  int last = g[0];
  for (size_t f = 1; f < n; ++f) {
    if (ign[f]) {
      last = -1;
      continue;
    }
    if (last != g[f] && last != -1 && g[f] != -1 && g[f - 1] != -1) {
      ++idsw;
      if (switches) switches->push_back({sequence, run.frames[f], label_id, last, g[f]});
    }
    if (f + 1 < n && g[f - 1] != g[f] && last != -1 && g[f] != -1 && g[f + 1] != -1) ++frag;
    if (g[f] != -1) last = g[f];
  }
  if (n > 1 && g[n - 2] != g[n - 1] && last != -1 && g[n - 1] != -1 && !ign[n - 1]) ++frag;
}

struct PassResult {
  KittiCounts counts;
  std::vector<double> match_scores;  // the score of every match, for the recall thresholds
};

// One evaluation of every sequence with the tracks whose score is >= threshold. When `hota` is
// given, the frames left after the ignore rules are appended to it (ids made unique per sequence).
PassResult runPass(const std::vector<SequenceFrames>& sequences, double threshold, const KittiProtocolOptions& o,
                   const std::string& cls, std::vector<TrackingFrame>* hota, std::vector<IdSwitch>* switches = nullptr) {
  PassResult out;
  KittiCounts& c = out.counts;
  double iou_sum = 0;
  std::map<std::pair<size_t, int>, int> hota_label_ids, hota_track_ids;
  const auto hotaId = [](std::map<std::pair<size_t, int>, int>& ids, size_t seq, int id) {
    return ids.emplace(std::make_pair(seq, id), static_cast<int>(ids.size())).first->second;
  };
  for (size_t s = 0; s < sequences.size(); ++s) {
    std::map<int, LabelRun> runs;
    const std::vector<double>& score = sequences[s].score;
    for (const FramePairs& f : sequences[s].frames) {
      std::vector<int> active;
      for (size_t j = 0; j < f.tracks.size(); ++j)
        if (!(score[f.tracks[j].key] < threshold)) active.push_back(static_cast<int>(j));
      const int nl = static_cast<int>(f.labels.size()), na = static_cast<int>(active.size());
      // The devkit's gate, as it writes it: cost 1 - IoU <= 1 - min_iou.
      const std::vector<int> col = assignAllowedPairs(nl, na, [&](int i, int a) -> std::optional<double> {
        const double cost = 1.0 - f.iou(i, active[a]);
        if (cost <= 1.0 - o.min_iou) return cost;
        return std::nullopt;
      });
      std::vector<int> label_of(na, -1);
      for (int i = 0; i < nl; ++i) {
        const Label& l = f.labels[i];
        LabelRun& run = runs[l.id];
        run.ids.push_back(col[i] >= 0 ? f.tracks[active[col[i]]].id : -1);
        run.ignored.push_back(l.ignored);
        run.frames.push_back(f.frame);
        if (col[i] >= 0) {
          label_of[col[i]] = i;
          ++c.tp;
          iou_sum += f.iou(i, active[col[i]]);
          out.match_scores.push_back(score[f.tracks[active[col[i]]].key]);
        }
        if (l.ignored)
          ++c.ignored_labels;
        else {
          ++c.labels;
          if (col[i] < 0) ++c.fn;
        }
      }
      TrackingFrame hf;
      for (int a = 0; a < na; ++a) {
        const Track& t = f.tracks[active[a]];
        const bool ignored = label_of[a] < 0 && t.ignorable;
        if (label_of[a] < 0) (ignored ? c.ignored_tracks : c.fp) += 1;
        if (hota && !ignored && (label_of[a] < 0 || !f.labels[label_of[a]].ignored)) {
          Box b = f.track_boxes[active[a]];
          b.type = cls;
          b.id = hotaId(hota_track_ids, s, t.id);
          hf.tracks.push_back({b, std::nullopt, false});
        }
      }
      if (hota) {
        for (int i = 0; i < nl; ++i) {
          if (f.labels[i].ignored) continue;
          Box b = f.label_boxes[i];
          b.type = cls;
          b.id = hotaId(hota_label_ids, s, f.labels[i].id);
          hf.truth.push_back({b, std::nullopt, false});
        }
        hota->push_back(std::move(hf));
      }
    }
    for (const auto& [id, run] : runs) countSwitches(run, c.idsw, c.frag, sequences[s].name, id, switches);
  }
  if (c.labels > 0) c.mota = 1.0 - static_cast<double>(c.fn + c.fp + c.idsw) / c.labels;
  if (c.tp > 0) c.motp = iou_sum / c.tp;
  return out;
}

// AB3DMOT's getThresholds: walking down the ranked match scores, the score at which recall first
// comes closest to each recall point 0, 1/40, 2/40, ...; the point 0 is dropped.
std::vector<std::pair<double, double>> recallThresholds(std::vector<double> scores, int num_gt, int recall_points) {
  std::sort(scores.begin(), scores.end(), std::greater<double>());
  std::vector<std::pair<double, double>> out;  // (threshold, recall)
  double current = 0;
  const size_t n = scores.size();
  for (size_t i = 0; i < n; ++i) {
    const double l = static_cast<double>(i + 1) / num_gt;
    const double r = i + 1 < n ? static_cast<double>(i + 2) / num_gt : l;
    if (r - current < current - l && i + 1 < n) continue;
    out.emplace_back(scores[i], current);
    current += 1.0 / recall_points;
  }
  if (!out.empty()) out.erase(out.begin());
  return out;
}

// sMOTA and MOTA at each recall point's threshold. `drift`: the scores drift from pass to pass as
// in AB3DMOT's script (SequenceFrames::reaverage); else every pass uses the tracks' mean scores.
KittiSweep sweep(std::vector<SequenceFrames> prepared, const std::vector<std::pair<double, double>>& thresholds,
                 const KittiCounts& all, const KittiProtocolOptions& o, const std::string& cls, bool drift) {
  KittiSweep out;
  out.best = all;
  if (all.labels == 0) return out;
  out.recall_points_reached = static_cast<int>(thresholds.size());
  double smota_sum = 0, mota_sum = 0, best_mota = 0;  // the script keeps all tracks unless some MOTA is > 0
  for (const auto& [threshold, recall] : thresholds) {
    if (drift)
      for (SequenceFrames& s : prepared) s.reaverage();
    const KittiCounts c = runPass(prepared, threshold, o, cls, nullptr).counts;
    const double n = c.labels;
    smota_sum += std::clamp(1.0 - (c.fn + c.fp + c.idsw - (1.0 - recall) * n) / (recall * n), 0.0, 1.0);
    mota_sum += *c.mota;
    if (*c.mota > best_mota) {
      best_mota = *c.mota;
      out.best = c;
      out.best_threshold = threshold;
    }
  }
  if (drift && out.best_threshold) {  // the script evaluates its best threshold once more, scores drifted again
    for (SequenceFrames& s : prepared) s.reaverage();
    out.best = runPass(prepared, *out.best_threshold, o, cls, nullptr).counts;
  }
  out.samota = smota_sum / o.recall_points;
  out.amota = mota_sum / o.recall_points;
  return out;
}

}  // namespace

std::map<std::string, KittiClassMetrics> evaluateKittiTracking(const std::vector<KittiSequence>& sequences,
                                                               const KittiProtocolOptions& options) {
  std::vector<std::string> classes;
  for (const std::string& c : options.classes) classes.push_back(lower(c));
  if (classes.empty()) {
    classes = {"car", "pedestrian"};
    const bool cyclists = std::any_of(sequences.begin(), sequences.end(), [](const KittiSequence& s) {
      return std::any_of(s.labels.begin(), s.labels.end(), [](const kitti::LabelRow& r) { return lower(r.type) == "cyclist"; });
    });
    if (cyclists) classes.push_back("cyclist");
  }
  std::map<std::string, KittiClassMetrics> out;
  for (const std::string& cls : classes) {
    std::vector<SequenceFrames> prepared;
    for (const KittiSequence& s : sequences) prepared.push_back(prepare(s, cls, options));
    KittiClassMetrics m;
    m.min_iou = options.min_iou;
    std::vector<TrackingFrame> hota_frames;
    const PassResult all = runPass(prepared, -std::numeric_limits<double>::infinity(), options, cls, &hota_frames);
    m.all = all.counts;
    m.hota = evaluateHota(hota_frames, MatchCriterion{MatchCriterion::Kind::Iou3d, 0.0, options.min_iou});
    // The denominator of recall is the devkit's num_gt = tp + fn (matches of ignored labels included).
    const auto thresholds = m.all.labels > 0 ? recallThresholds(all.match_scores, m.all.tp + m.all.fn, options.recall_points)
                                             : std::vector<std::pair<double, double>>();
    m.sweep = sweep(prepared, thresholds, all.counts, options, cls, false);
    m.sweep_ab3dmot = sweep(prepared, thresholds, all.counts, options, cls, true);
    runPass(prepared, m.sweep.best_threshold.value_or(-std::numeric_limits<double>::infinity()), options, cls, nullptr,
            &m.best_switches);
    out[cls] = std::move(m);
  }
  return out;
}

}  // namespace dlslot::eval
