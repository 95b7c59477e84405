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
  // Rows holding any point: the rows are finer than the beams, so most rows are empty and the
  // neighbourhood search skips them (a third of the lookups).
  std::vector<uint8_t> row_used(rows, 0);
  for (int i = 0; i < n; ++i) {
    if (!obstacle[i]) continue;
    row_used[layout.row[i]] = 1;
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
        if (!row_used[r]) continue;
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
  // Small pieces are kept here: joinOverlappingClusters() may give them a home.
  clusters.erase(std::remove_if(clusters.begin(), clusters.end(), [](const std::vector<int>& c) { return c.size() < 3; }),
                 clusters.end());
  return clusters;
}

std::vector<std::vector<int>> joinOverlappingClusters(const PointCloud& scan, std::vector<std::vector<int>> clusters,
                                                      double margin_m, double max_diagonal_m, int min_points) {
  struct Aabb {
    float x0, y0, x1, y1;
  };
  const int n = static_cast<int>(clusters.size());
  std::vector<Aabb> box(n);
  for (int k = 0; k < n; ++k) {
    Aabb b{1e9f, 1e9f, -1e9f, -1e9f};
    for (int i : clusters[k]) {
      b.x0 = std::min(b.x0, scan(0, i));
      b.y0 = std::min(b.y0, scan(1, i));
      b.x1 = std::max(b.x1, scan(0, i));
      b.y1 = std::max(b.y1, scan(1, i));
    }
    box[k] = b;
  }
  const float m = static_cast<float>(margin_m), d2 = static_cast<float>(max_diagonal_m * max_diagonal_m);
  // Object-sized clusters only, sorted by x so the overlap search stops early.
  std::vector<int> order;
  for (int k = 0; k < n; ++k) {
    const float dx = box[k].x1 - box[k].x0, dy = box[k].y1 - box[k].y0;
    if (dx * dx + dy * dy <= d2) order.push_back(k);
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) { return box[a].x0 < box[b].x0; });
  std::vector<int> parent(n);
  for (int k = 0; k < n; ++k) parent[k] = k;
  auto root = [&](int k) {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];
    return k;
  };
  for (size_t a = 0; a < order.size(); ++a) {
    for (size_t b = a + 1; b < order.size(); ++b) {
      const int i = order[a], j = order[b];
      if (box[j].x0 > box[i].x1 + m) break;
      if (box[j].y0 > box[i].y1 + m || box[i].y0 > box[j].y1 + m) continue;
      const int ri = root(i), rj = root(j);
      if (ri == rj) continue;
      const Aabb u{std::min(box[ri].x0, box[rj].x0), std::min(box[ri].y0, box[rj].y0), std::max(box[ri].x1, box[rj].x1),
                   std::max(box[ri].y1, box[rj].y1)};
      const float dx = u.x1 - u.x0, dy = u.y1 - u.y0;
      if (dx * dx + dy * dy > d2) continue;
      parent[rj] = ri;
      box[ri] = u;  // the root's box is the joined one
    }
  }
  std::vector<std::vector<int>> out;
  std::vector<int> slot(n, -1);
  for (int k = 0; k < n; ++k) {
    const int r = root(k);
    if (slot[r] < 0) {
      slot[r] = static_cast<int>(out.size());
      out.emplace_back();
    }
    std::vector<int>& dst = out[slot[r]];
    dst.insert(dst.end(), clusters[k].begin(), clusters[k].end());
  }
  out.erase(std::remove_if(out.begin(), out.end(),
                           [&](const std::vector<int>& c) { return static_cast<int>(c.size()) < min_points; }),
            out.end());
  return out;
}

}  // namespace dlslot::detector
