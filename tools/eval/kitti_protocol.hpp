// The KITTI tracking protocol as the KITTI devkit (evaluate_tracking.py) and AB3DMOT
// (scripts/KITTI/evaluate.py, its 3-D setting) compute it, so that our numbers stand next to
// published ones. LCM-free and scan-free: label rows and results rows in, per-class metrics out.
//
// Per class (car, pedestrian, cyclist), frame by frame, in the rectified camera frame:
// - labels and tracks of the class and of its neighbour class (Van for car, Person_sitting for
//   pedestrian) take part; DontCare labels are 2-D ignore regions; rows with track id -1 are skipped;
// - labels and tracks are matched by the Hungarian algorithm on 1 - 3-D IoU, among pairs with
//   3-D IoU >= min_iou (0.25, AB3DMOT's setting), whatever their class within the class's pair;
// - a label is ignored (neither TP nor FN; a match to it is neither TP nor FP) when its truncation
//   (an integer level in tracking labels) exceeds max_truncation (0), its occlusion exceeds
//   max_occlusion (2), or it is of the neighbour class;
// - an unmatched track is ignored (not an FP) when it is of the neighbour class, when its 2-D box
//   is at most min_height_px (25) tall, or when more than half of its 2-D box lies in one DontCare
//   box. (The devkit applies the height limit to tracks only, not to labels.)
// - IDSW and FRAG are counted on each label's run of matched track ids, ignored frames skipped,
//   exactly as the devkit does (a switch needs the label matched in its previous frame; a
//   fragment is a change of id or a re-start after a gap);
// - MOTA = 1 - (FN + FP + IDSW) / labels (ignored labels excluded), MOTP = mean 3-D IoU of all
//   matches; tp counts every match, like the devkit's "True Positives" (matches of ignored labels
//   included), so tp + fn can exceed `labels`;
// - sAMOTA and AMOTA (Weng et al., "AB3DMOT", IROS 2020): every track gets the mean score of its
//   rows in its sequence; the scores of the matches of the all-tracks pass, ranked, give one score
//   threshold per recall point r = 1/40, 2/40, ... (as far as the tracks reach); at each, tracks
//   whose mean is below the threshold are dropped and sMOTA_r = max(0, min(1, 1 - (FN + FP + IDSW -
//   (1 - r) * labels) / (r * labels))); sAMOTA = sum sMOTA_r / 40, AMOTA = sum MOTA_r / 40 (recall
//   points the tracks never reach count 0). Over several sequences the counts and the score
//   ranking are pooled, as AB3DMOT does: one sAMOTA, not a mean of per-sequence values. The same
//   sweep is also computed exactly as AB3DMOT's script does it (KittiClassMetrics::sweep_ab3dmot).
// - HOTA (hota.hpp) with 3-D IoU as similarity, on the labels and tracks left after the ignore
//   rules (ignored labels, ignored tracks and tracks matched to ignored labels removed).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dlslot/kitti.hpp"
#include "hota.hpp"

namespace dlslot::eval {

// One sequence: its label_02 rows (DontCare included) and the results rows (track id, type, the
// camera box, the 2-D box and the score; a row without score counts as -1, as in the devkit).
struct KittiSequence {
  std::string name;                     // for messages, e.g. "0002"
  std::vector<kitti::LabelRow> labels;
  std::vector<kitti::LabelRow> tracks;
  std::vector<int> frames;  // frames evaluated, ascending; empty: 0 .. the last frame any label or track row names
};

struct KittiProtocolOptions {
  double min_iou = 0.25;
  int max_truncation = 0, max_occlusion = 2;
  double min_height_px = 25;
  int recall_points = 40;
  // "car", "pedestrian", "cyclist". Empty: car and pedestrian, and cyclist when a label is one.
  std::vector<std::string> classes;
};

struct KittiCounts {
  int labels = 0;          // labels scored (ignored ones excluded)
  int ignored_labels = 0;
  int ignored_tracks = 0;  // unmatched tracks ignored (neighbour class, small, DontCare)
  int tp = 0, fp = 0, fn = 0, idsw = 0, frag = 0;
  std::optional<double> mota, motp;  // null without labels / without matches
};

// The score sweep over the recall points.
struct KittiSweep {
  std::optional<double> samota, amota;   // null without labels
  int recall_points_reached = 0;         // of options.recall_points
  KittiCounts best;                      // at the recall point's threshold with the highest MOTA
                                         // (AB3DMOT's "best results with single threshold"); = all when none is > 0
  std::optional<double> best_threshold;  // null: all tracks
};

// One identity switch: a label matched to track `from` in its previous frame and to `to` at `frame`.
struct IdSwitch {
  std::string sequence;
  int frame = 0, label_id = -1, from = -1, to = -1;
};

struct KittiClassMetrics {
  double min_iou = 0.25;  // the match gate these were computed with
  KittiCounts all;        // every track, no score threshold
  KittiSweep sweep;       // tracks kept when their mean score >= the threshold
  // The same as AB3DMOT's script computes it, to the digit: it overwrites every row's score with
  // its track's mean at each pass and averages again at the next, so the means drift by rounding
  // and a track whose mean is itself the threshold is dropped at some recall points (with raw
  // PointRCNN logits this can zero half of them: sequence 0002, pedestrian, 0.18 instead of 0.69).
  KittiSweep sweep_ab3dmot;
  std::optional<Hota> hota;
  std::vector<IdSwitch> best_switches;  // the identity switches at sweep.best_threshold (all tracks when none)
};

// Per class name, the metrics over all sequences together. Throws std::invalid_argument naming the
// sequence and frame when a track id appears twice in one frame (the devkit refuses such files).
std::map<std::string, KittiClassMetrics> evaluateKittiTracking(const std::vector<KittiSequence>& sequences,
                                                               const KittiProtocolOptions& options = {});

}  // namespace dlslot::eval
