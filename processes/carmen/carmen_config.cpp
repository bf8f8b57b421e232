#include "carmen_config.hpp"

#include "carmen_log.hpp"
#include "config.hpp"

namespace traverse::carmen {

std::optional<std::string> validate(const CarmenConfig& c) {
  ConfigCheck check;
  check.require(parse_flaser_geometry(c.flaser_geometry).has_value(), "flaser_geometry",
                "must be one of standard, half_open, closed, centered, reversed, got '" +
                    c.flaser_geometry + "'");
  check.not_negative("range_min_m", c.range_min_m);
  check.require(c.range_max_m > c.range_min_m, "range_max_m", "must exceed range_min_m");
  check.not_negative("no_return_code_m", c.no_return_code_m);
  check.require(c.no_return_code_m == 0.0 || c.no_return_code_m > c.range_min_m, "no_return_code_m",
                "must be 0 (found in the data) or exceed range_min_m");
  check.require(c.no_return_min_fraction > 0.0 && c.no_return_min_fraction <= 1.0,
                "no_return_min_fraction", "must be in (0, 1]");
  check.in_range("max_beams", c.max_beams, 1, kMaxBeams);
  check.in_range("max_timestamp_quantum_s", c.max_timestamp_quantum_s, 1e-6, 1e9);
  check.in_range("nominal_scan_period_s", c.nominal_scan_period_s, 1e-6, 3600.0);
  check.require(c.odometry_source == "auto" || c.odometry_source == "odom" ||
                    c.odometry_source == "laser" || c.odometry_source == "none",
                "odometry_source",
                "must be one of auto, odom, laser, none, got '" + c.odometry_source + "'");
  check.nested("odometry_noise", validate(c.odometry_noise));
  return check.problem();
}

}  // namespace traverse::carmen
