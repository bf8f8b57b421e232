#include "deskew.hpp"

#include <cmath>

namespace traverse::frontend {

void deskew_points(std::vector<Eigen::Vector2d>& points_base, const std::vector<int64_t>& utimes,
                   int64_t utime_ref, const std::function<double(int64_t)>& heading_change,
                   const Eigen::Vector2d& velocity_base, bool translation) {
  for (std::size_t i = 0; i < points_base.size(); ++i) {
    if (utimes[i] == utime_ref) continue;
    // T_ref_i: the base at the point's time seen from the base at the reference time. Over a
    // sweep (tens of ms) the translation is well approximated by velocity times time.
    const double dtheta = heading_change(utimes[i]);
    const double c = std::cos(dtheta), s = std::sin(dtheta);
    const Eigen::Vector2d& p = points_base[i];
    Eigen::Vector2d q(c * p.x() - s * p.y(), s * p.x() + c * p.y());
    if (translation) q += velocity_base * (1e-6 * static_cast<double>(utimes[i] - utime_ref));
    points_base[i] = q;
  }
}

}  // namespace traverse::frontend
