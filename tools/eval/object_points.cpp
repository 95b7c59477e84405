#include "object_points.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace dlslot::eval {

std::vector<ObjectPoints> countObjectPoints(int frame, const PointCloud& scan, const std::vector<Box>& labels,
                                            const ObjectPointOptions& options) {
  std::vector<ObjectPoints> out;
  out.reserve(labels.size());
  for (const Box& box : labels) {
    const Pose T_box_lidar = box.pose().inverse();
    const Eigen::Vector3d half = 0.5 * box.size;
    int n = 0;
    for (Eigen::Index i = 0; i < scan.cols(); ++i) {
      const Eigen::Vector3d p = T_box_lidar * scan.col(i).head<3>().cast<double>();
      if (std::abs(p.x()) <= half.x() + options.margin_m && std::abs(p.y()) <= half.y() + options.margin_m &&
          p.z() <= half.z() + options.margin_m && p.z() >= -half.z() + options.bottom_band_m)
        ++n;
    }
    out.push_back({frame, box.type, box.center.head<2>().norm(), n});
  }
  return out;
}

namespace {
double quantile(std::vector<int>& v, double q) {  // v non-empty; nearest rank on the sorted values
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(pos);
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}
}  // namespace

std::vector<ObjectPointRow> summariseObjectPoints(const std::vector<ObjectPoints>& samples,
                                                  const ObjectPointOptions& options) {
  const std::vector<double>& e = options.range_edges_m;
  if (e.size() < 2 || !std::is_sorted(e.begin(), e.end()))
    throw std::invalid_argument("object points: range bins need two or more increasing edges");
  std::map<std::pair<std::string, size_t>, std::vector<int>> bins;
  for (const ObjectPoints& s : samples) {
    const auto it = std::upper_bound(e.begin(), e.end(), s.range_m);
    if (it == e.begin() || it == e.end()) continue;  // outside the bins
    bins[{s.type, static_cast<size_t>(it - e.begin()) - 1}].push_back(s.points);
  }
  std::vector<ObjectPointRow> rows;
  for (auto& [key, counts] : bins) {
    ObjectPointRow r;
    r.type = key.first;
    r.range_lo_m = e[key.second];
    r.range_hi_m = e[key.second + 1];
    r.objects = static_cast<int>(counts.size());
    r.p25 = quantile(counts, 0.25);
    r.median = quantile(counts, 0.5);
    r.p75 = quantile(counts, 0.75);
    rows.push_back(r);
  }
  return rows;
}

std::string objectPointTable(const std::vector<ObjectPointRow>& rows) {
  std::ostringstream s;
  s << "| class | range m | objects | points: median | 25-75 % |\n|---|---|---|---|---|\n";
  char line[160];
  for (const ObjectPointRow& r : rows) {
    std::snprintf(line, sizeof line, "| %s | %.0f-%.0f | %d | %.0f | %.0f-%.0f |\n", r.type.c_str(), r.range_lo_m,
                  r.range_hi_m, r.objects, r.median, r.p25, r.p75);
    s << line;
  }
  return s.str();
}

void writeObjectPointsCsv(const std::string& path, const std::vector<ObjectPoints>& samples) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot write");
  f << "frame,type,range_m,points\n";
  for (const ObjectPoints& s : samples) f << s.frame << ',' << s.type << ',' << s.range_m << ',' << s.points << '\n';
  if (!f) throw std::runtime_error(path + ": write failed");
}

}  // namespace dlslot::eval
