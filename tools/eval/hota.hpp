// HOTA (Luiten et al., IJCV 2021), as TrackEval computes it: for each localisation threshold
// alpha = 0.05, 0.10, ..., 0.95, labels and tracks are matched per frame by maximising the
// global alignment score times the similarity, pairs with similarity >= alpha are true positives,
// DetA = TP / (TP + FN + FP), AssA = mean over TPs of the association IoU of their (label, track)
// pair, HOTA_alpha = sqrt(DetA * AssA); HOTA is the mean over alpha.
#pragma once

#include <optional>
#include <vector>

#include "tracking_frames.hpp"

namespace dlslot::eval {

struct Hota {
  double hota = 0, deta = 0, assa = 0, loca = 0;  // means over alpha
  std::vector<double> alphas, hota_by_alpha;
};

// The similarity is MatchCriterion::similarity (IoU, or 1 - d / gate for the distance line).
// Null when there are neither labels nor tracks.
std::optional<Hota> evaluateHota(const std::vector<TrackingFrame>& frames, const MatchCriterion& criterion);

}  // namespace dlslot::eval
