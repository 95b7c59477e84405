#include "detector/detection_eval.hpp"

#include <algorithm>
#include <tuple>

namespace dlslot::detector {

bool EvalClass::holds(const std::string& type) const { return std::find(types.begin(), types.end(), type) != types.end(); }

std::vector<EvalClass> defaultEvalClasses() {
  return {{"Car", {"Car", "Van", "Truck"}}, {"Pedestrian", {"Pedestrian", "Person_sitting"}}, {"Cyclist", {"Cyclist"}}};
}

void MatchCounts::add(const MatchCounts& o) {
  labels += o.labels;
  detections += o.detections;
  matched += o.matched;
  ignored += o.ignored;
}

MatchCounts matchFrame(const std::vector<Box>& labels, const std::vector<Box>& detections, const EvalClass& cls,
                       const EvalOptions& opt, const std::function<bool(const Box&)>& ignore) {
  auto counted = [&](const Box& b) { return cls.holds(b.type) && b.center.head<2>().norm() <= opt.max_range_m; };
  std::vector<int> L, D;
  for (int i = 0; i < static_cast<int>(labels.size()); ++i)
    if (counted(labels[i])) L.push_back(i);
  for (int j = 0; j < static_cast<int>(detections.size()); ++j)
    if (counted(detections[j])) D.push_back(j);
  std::vector<std::tuple<double, int, int>> pairs;
  for (int a = 0; a < static_cast<int>(L.size()); ++a)
    for (int b = 0; b < static_cast<int>(D.size()); ++b) {
      const double d = (labels[L[a]].center.head<2>() - detections[D[b]].center.head<2>()).norm();
      if (d <= opt.max_distance_m) pairs.emplace_back(d, a, b);
    }
  std::sort(pairs.begin(), pairs.end());
  std::vector<char> label_used(L.size(), 0), det_used(D.size(), 0);
  MatchCounts m;
  m.labels = static_cast<int>(L.size());
  for (const auto& [d, a, b] : pairs) {
    if (label_used[a] || det_used[b]) continue;
    label_used[a] = det_used[b] = 1;
    ++m.matched;
  }
  for (int b = 0; b < static_cast<int>(D.size()); ++b) {
    if (!det_used[b] && ignore && ignore(detections[D[b]]))
      ++m.ignored;
    else
      ++m.detections;
  }
  return m;
}

}  // namespace dlslot::detector
