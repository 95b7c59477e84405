#include "tracking_frames.hpp"

#include <algorithm>
#include <cstdio>

#include "assignment.hpp"
#include "box_overlap.hpp"
#include "dlslot/kitti.hpp"

namespace dlslot::eval {

bool MatchCriterion::geometricMatch(const Box& truth, const Box& track) const {
  if (kind == Kind::CentreDistance) return bevDistance(truth, track) <= max_distance_m;
  return iou3d(truth, track) >= min_iou;
}

bool MatchCriterion::matches(const Box& truth, const Box& track) const {
  return kitti::classesCompatible(truth.type, track.type) && geometricMatch(truth, track);
}

double MatchCriterion::cost(const Box& truth, const Box& track) const {
  return kind == Kind::CentreDistance ? bevDistance(truth, track) : 1.0 - iou3d(truth, track);
}

double MatchCriterion::similarity(const Box& truth, const Box& track) const {
  if (!kitti::classesCompatible(truth.type, track.type)) return 0.0;
  if (kind == Kind::Iou3d) return iou3d(truth, track);
  return std::max(0.0, 1.0 - bevDistance(truth, track) / max_distance_m);
}

std::string MatchCriterion::describe() const {
  char buf[64];
  if (kind == Kind::CentreDistance)
    std::snprintf(buf, sizeof buf, "centre distance <= %g m", max_distance_m);
  else
    std::snprintf(buf, sizeof buf, "3D IoU >= %g", min_iou);
  return buf;
}

void restrictClasses(std::vector<TrackingFrame>& frames, const std::vector<std::string>& classes) {
  if (classes.empty()) return;
  const auto evaluated = [&](const Box& b) { return std::find(classes.begin(), classes.end(), b.type) != classes.end(); };
  const auto neighbouring = [&](const Box& b) {
    return std::any_of(classes.begin(), classes.end(), [&](const std::string& c) { return kitti::classesCompatible(c, b.type); });
  };
  for (TrackingFrame& f : frames) {
    std::vector<Object> kept;
    for (Object& o : f.truth) {
      if (evaluated(o.box))
        kept.push_back(std::move(o));
      else if (neighbouring(o.box))
        f.ignore.push_back(o.box);
    }
    f.truth = std::move(kept);
    f.tracks.erase(std::remove_if(f.tracks.begin(), f.tracks.end(), [&](const Object& o) { return !evaluated(o.box); }),
                   f.tracks.end());
  }
}

void dropIgnoredTracks(std::vector<TrackingFrame>& frames, const MatchCriterion& criterion) {
  for (TrackingFrame& f : frames) {
    if (f.ignore.empty() || f.tracks.empty()) continue;
    const int nt = static_cast<int>(f.truth.size()), nh = static_cast<int>(f.tracks.size());
    std::vector<bool> matched(nh, false);
    const std::vector<int> col = assignAllowedPairs(nt, nh, [&](int i, int j) -> std::optional<double> {
      const Box &g = f.truth[i].box, &h = f.tracks[j].box;
      if (!criterion.matches(g, h)) return std::nullopt;
      return criterion.cost(g, h);
    });
    for (int c : col)
      if (c >= 0) matched[c] = true;
    std::vector<Object> kept;
    for (int j = 0; j < nh; ++j) {
      const Box& h = f.tracks[j].box;
      const bool ignored = !matched[j] && std::any_of(f.ignore.begin(), f.ignore.end(), [&](const Box& region) {
        return footprintContains(region, h.center) || criterion.geometricMatch(region, h);
      });
      if (!ignored) kept.push_back(std::move(f.tracks[j]));
    }
    f.tracks = std::move(kept);
  }
}

}  // namespace dlslot::eval
