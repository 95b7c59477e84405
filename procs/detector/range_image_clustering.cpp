#include "detector/range_image_clustering.hpp"

#include <algorithm>

namespace dlslot::detector {

std::vector<std::vector<int>> clusterRangeImage(const PointCloud& scan, const ScanLayout& layout,
                                                const std::vector<uint8_t>& obstacle, const ClusteringConfig& cfg) {
  const int rows = layout.rows, cols = layout.columns;
  const int n = static_cast<int>(scan.cols());
  // The image: the nearest obstacle point of each pixel.
  std::vector<int> pixel(static_cast<size_t>(rows) * cols, -1);
  std::vector<int> spare;  // obstacle points behind a nearer one in their pixel
  for (int i = 0; i < n; ++i) {
    if (!obstacle[i]) continue;
    int& p = pixel[static_cast<size_t>(layout.row[i]) * cols + layout.column[i]];
    if (p < 0) {
      p = i;
    } else if (layout.range[i] < layout.range[p]) {
      spare.push_back(p);
      p = i;
    } else {
      spare.push_back(i);
    }
  }
  const float d0 = static_cast<float>(cfg.distance_m), dk = static_cast<float>(cfg.distance_per_m);
  auto threshold2 = [&](int i) {
    const float d = std::max(d0, dk * layout.range[i]);
    return d * d;
  };
  auto dist2 = [&](int a, int b) {
    const float dx = scan(0, a) - scan(0, b), dy = scan(1, a) - scan(1, b), dz = scan(2, a) - scan(2, b);
    return dx * dx + dy * dy + dz * dz;
  };
  std::vector<int> label(n, -1);
  std::vector<std::vector<int>> clusters;
  std::vector<int> stack;
  const int R = cfg.neighbour_rows, C = cfg.neighbour_columns;
  for (int i = 0; i < n; ++i) {
    if (!obstacle[i] || label[i] >= 0) continue;
    if (pixel[static_cast<size_t>(layout.row[i]) * cols + layout.column[i]] != i) continue;  // a spare point
    const int id = static_cast<int>(clusters.size());
    clusters.emplace_back();
    std::vector<int>& members = clusters.back();
    label[i] = id;
    stack.assign(1, i);
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      members.push_back(p);
      const float t2 = threshold2(p);
      const int r0 = std::max(0, layout.row[p] - R), r1 = std::min(rows - 1, layout.row[p] + R);
      for (int r = r0; r <= r1; ++r) {
        const int* line = &pixel[static_cast<size_t>(r) * cols];
        for (int dc = -C; dc <= C; ++dc) {
          int c = layout.column[p] + dc;
          c += (c < 0) ? cols : (c >= cols ? -cols : 0);  // the image wraps around at the back
          const int q = line[c];
          if (q < 0 || label[q] >= 0) continue;
          if (dist2(p, q) < t2) {
            label[q] = id;
            stack.push_back(q);
          }
        }
      }
    }
  }
  // Points hidden behind a nearer one of their pixel: with that point's cluster when close to it.
  for (int i : spare) {
    const int p = pixel[static_cast<size_t>(layout.row[i]) * cols + layout.column[i]];
    if (label[p] >= 0 && dist2(i, p) < threshold2(p)) clusters[label[p]].push_back(i);
  }
  std::vector<std::vector<int>> out;
  for (auto& c : clusters)
    if (static_cast<int>(c.size()) >= cfg.min_points) out.push_back(std::move(c));
  return out;
}

}  // namespace dlslot::detector
