#include "detector/score_calibration.hpp"

#include <algorithm>
#include <stdexcept>

namespace dlslot::detector {

double ScoreTable::operator()(double x) const {
  if (x <= raw.front()) return calibrated.front();
  if (x >= raw.back()) return calibrated.back();
  const size_t k = static_cast<size_t>(std::upper_bound(raw.begin(), raw.end(), x) - raw.begin());  // raw[k-1] <= x < raw[k]
  const double t = (x - raw[k - 1]) / (raw[k] - raw[k - 1]);
  return calibrated[k - 1] + t * (calibrated[k] - calibrated[k - 1]);
}

void ScoreTable::validate() const {
  if (raw.empty() || raw.size() != calibrated.size())
    throw std::invalid_argument("expected raw and calibrated of the same size, at least one knot");
  for (size_t k = 1; k < raw.size(); ++k) {
    if (!(raw[k] > raw[k - 1])) throw std::invalid_argument("raw: expected strictly increasing knots");
    if (!(calibrated[k] >= calibrated[k - 1]))
      throw std::invalid_argument("calibrated: expected non-decreasing values (a higher raw score is never less likely right)");
  }
}

double ScoreCalibration::apply(const std::string& type, double raw_score) const {
  if (type == "Car" || type == "Van" || type == "Truck") return vehicle(raw_score);
  if (type == "Pedestrian") return pedestrian(raw_score);
  if (type == "Cyclist") return cyclist(raw_score);
  return raw_score;
}

ScoreCalibration ScoreCalibration::read(ConfigSection s) {
  ScoreCalibration c;
  auto table = [&](const std::string& key, ScoreTable& t) {
    ConfigSection k = s.section(key);
    k.get("raw", t.raw);
    k.get("calibrated", t.calibrated);
    k.finish();
    try {
      t.validate();
    } catch (const std::invalid_argument& e) {
      throw ConfigError(k.file() + ": " + k.path() + ": " + e.what());
    }
  };
  table("vehicle", c.vehicle);
  table("pedestrian", c.pedestrian);
  table("cyclist", c.cyclist);
  s.finish();
  return c;
}

}  // namespace dlslot::detector
