#include "detector/scan_layout.hpp"

#include <algorithm>
#include <cmath>

namespace dlslot::detector {

float fastAtan2(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float mx = std::max(ax, ay), mn = std::min(ax, ay);
  if (mx == 0.0f) return 0.0f;
  const float a = mn / mx;
  const float s = a * a;
  // Minimax polynomial for atan on [0, 1] (max error ~1e-5 rad).
  float r = ((((-0.0117212f * s + 0.05265332f) * s - 0.11643287f) * s + 0.19354346f) * s - 0.33262347f) * s *
                a +
            0.99997726f * a;
  if (ay > ax) r = 1.57079637f - r;
  if (x < 0) r = 3.14159274f - r;
  return y < 0 ? -r : r;
}

ScanLayout layoutScan(const PointCloud& scan, const DetectorConfig& cfg) {
  ScanLayout L;
  L.sectors = cfg.ground.sectors;
  L.bin_m = cfg.ground.bin_m;
  L.bins = static_cast<int>(std::ceil(cfg.window.max_range_m / cfg.ground.bin_m));
  L.columns = cfg.clustering.columns;
  L.row_step = static_cast<float>(cfg.clustering.row_step);
  // Rows span tan(elevation) from below the HDL-64E's lowest beam (-24.9 deg) to above its top
  // (+2 deg), with a margin for other sensors; points beyond are clamped to the edge rows.
  L.row_tan_min = -0.55f;
  const float row_tan_max = 0.15f;
  L.rows = static_cast<int>(std::ceil((row_tan_max - L.row_tan_min) / L.row_step));
  const int n = static_cast<int>(scan.cols());
  L.cell.assign(n, -1);
  L.column.assign(n, 0);
  L.row.assign(n, 0);
  L.range.assign(n, 0.0f);
  const float rmin2 = static_cast<float>(cfg.window.min_range_m * cfg.window.min_range_m);
  const float rmax2 = static_cast<float>(cfg.window.max_range_m * cfg.window.max_range_m);
  const float col_scale = static_cast<float>(L.columns / (2.0 * M_PI));
  const float inv_bin = static_cast<float>(1.0 / L.bin_m);
  const float inv_row = 1.0f / L.row_step;
  for (int i = 0; i < n; ++i) {
    const float x = scan(0, i), y = scan(1, i), z = scan(2, i);
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) continue;
    const float r2 = x * x + y * y;
    if (r2 < rmin2 || r2 >= rmax2) continue;
    const float rho = std::sqrt(r2);
    int col = static_cast<int>((fastAtan2(y, x) + static_cast<float>(M_PI)) * col_scale);
    col = std::min(std::max(col, 0), L.columns - 1);
    const int sector = col * L.sectors / L.columns;
    const int bin = std::min(static_cast<int>(rho * inv_bin), L.bins - 1);
    int row = static_cast<int>((z / rho - L.row_tan_min) * inv_row);
    row = std::min(std::max(row, 0), L.rows - 1);
    L.cell[i] = sector * L.bins + bin;
    L.column[i] = static_cast<int16_t>(col);
    L.row[i] = static_cast<int16_t>(row);
    L.range[i] = rho;
    ++L.num_used;
  }
  return L;
}

}  // namespace dlslot::detector
