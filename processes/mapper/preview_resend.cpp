#include "preview_resend.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

namespace traverse::mapper {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

PreviewResend::PreviewResend(double cell_m, int64_t max_bytes, bool background)
    : cell_m_(cell_m), max_bytes_(max_bytes), background_(background) {}

PreviewResend::~PreviewResend() {
  if (pass_.valid()) pass_.wait();
}

int64_t PreviewResend::bytes() const {
  return points_ * kKeptPointBytes +
         static_cast<int64_t>(kept_.size() + pass_profiles_) * kKeptProfileBytes;
}

void PreviewResend::add(const PreviewProfile& profile) {
  if (profile.p_base_mm.empty()) return;
  auto [it, fresh] = kept_.try_emplace(profile.utime);
  KeptProfile& k = it->second;
  if (fresh) {
    k.x = static_cast<float>(profile.T_world_base.x());
    k.y = static_cast<float>(profile.T_world_base.y());
    k.theta = static_cast<float>(profile.T_world_base.theta());
  }
  k.p_base_mm.reserve(k.p_base_mm.size() + profile.p_base_mm.size());
  k.p_base_mm.insert(k.p_base_mm.end(), profile.p_base_mm.begin(), profile.p_base_mm.end());
  points_ += static_cast<int64_t>(profile.p_base_mm.size());
  if (bytes() > max_bytes_ && !pass_.valid()) start_pass();
}

PreviewResend::Pass PreviewResend::run(KeptProfiles kept, double cell_m, int64_t max_bytes) {
  const auto t0 = std::chrono::steady_clock::now();
  Pass pass{std::move(kept), 0, 0, 0};
  pass.cell_m = thin_earliest_per_cell(pass.kept, cell_m, max_bytes);
  for (const auto& [utime, k] : pass.kept) pass.points += static_cast<int64_t>(k.p_base_mm.size());
  pass.seconds = seconds_since(t0);
  return pass;
}

void PreviewResend::start_pass() {
  const auto t0 = std::chrono::steady_clock::now();
  pass_profiles_ = kept_.size();
  pass_points_ = points_;
  KeptProfiles given = std::move(kept_);
  kept_.clear();  // what arrives from now on
  if (background_) {
    pass_ = std::async(std::launch::async, [given = std::move(given), cell_m = cell_m_,
                                            max_bytes = max_bytes_]() mutable {
      return run(std::move(given), cell_m, max_bytes);
    });
  } else {
    merge(run(std::move(given), cell_m_, max_bytes_));
  }
  count_blocked(seconds_since(t0));
}

bool PreviewResend::poll() {
  if (!pass_.valid() || pass_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    return false;
  }
  const auto t0 = std::chrono::steady_clock::now();
  merge(pass_.get());
  // What arrived during the pass may have filled the store again, and add() may not come again
  // (the end of a route): the next pass starts now rather than with the next point.
  count_blocked(seconds_since(t0));
  if (bytes() > max_bytes_) start_pass();  // counts its own hold-up
  return true;
}

void PreviewResend::wait() {
  while (pass_.valid()) {
    merge(pass_.get());
    // What arrived during the pass may have filled the store again.
    if (bytes() > max_bytes_) start_pass();
  }
}

void PreviewResend::merge(Pass pass) {
  ++counters_.compactions;
  counters_.points_compacted += pass_points_ - pass.points;
  counters_.profiles_compacted += static_cast<int64_t>(pass_profiles_ - pass.kept.size());
  counters_.compact_total_s += pass.seconds;
  counters_.compact_max_s = std::max(counters_.compact_max_s, pass.seconds);
  // What arrived meanwhile goes after the thinned store; a part of a profile in it joins it.
  int64_t points = pass.points;
  for (auto& [utime, k] : kept_) {
    points += static_cast<int64_t>(k.p_base_mm.size());
    auto [it, fresh] = pass.kept.try_emplace(utime, std::move(k));
    if (!fresh) {
      it->second.p_base_mm.insert(it->second.p_base_mm.end(), k.p_base_mm.begin(),
                                  k.p_base_mm.end());
    }
  }
  kept_ = std::move(pass.kept);
  points_ = points;
  cell_m_ = pass.cell_m;
  pass_profiles_ = 0;
  pass_points_ = 0;
  // An answer under way that was inside a profile goes on from that profile's first point: the
  // thinned profile's points are no longer where they were (some go twice rather than none
  // lost). A stop inside a profile moves to its end for the same reason.
  if (resending_) {
    next_.point = 0;
    if (stop_.point > 0) stop_.point = std::numeric_limits<std::size_t>::max();
    settle();
  }
}

void PreviewResend::count_blocked(double s) {
  counters_.blocked_total_s += s;
  counters_.blocked_max_s = std::max(counters_.blocked_max_s, s);
}

PreviewResend::Mark PreviewResend::answer() {
  if (resending_) {
    // Joined: on to the newest profile, then round to here.
    stop_ = next_;
    wrapped_ = false;
  } else {
    resending_ = points_ > 0;
    next_ = stop_ = {std::numeric_limits<int64_t>::min(), 0};
    wrapped_ = false;
    lap_ = 0;
  }
  return {lap_, next_};
}

bool PreviewResend::went_round(const Mark& mark) const {
  return !resending_ || lap_ > mark.lap + 1 || (lap_ == mark.lap + 1 && next_ >= mark.at);
}

void PreviewResend::settle() {
  auto it = kept_.lower_bound(next_.utime);
  if (it != kept_.end() && it->first == next_.utime && next_.point >= it->second.p_base_mm.size()) {
    ++it;
  }
  if (it == kept_.end() && !wrapped_) {
    wrapped_ = true;
    ++lap_;
    it = kept_.begin();
    next_ = {std::numeric_limits<int64_t>::min(), 0};
  }
  if (it == kept_.end()) {
    resending_ = false;
    return;
  }
  if (it->first != next_.utime) next_ = {it->first, 0};
  resending_ = !wrapped_ || next_ < stop_;
}

std::vector<PreviewProfile> PreviewResend::next(std::size_t max_points) {
  std::vector<PreviewProfile> out;
  if (pass_.valid()) return out;
  if (resending_) settle();
  std::size_t n = 0;
  while (resending_ && n < max_points) {
    const auto it = kept_.find(next_.utime);  // settle() put the position on a kept profile
    const KeptProfile& k = it->second;
    std::size_t end = k.p_base_mm.size();
    if (wrapped_ && stop_.utime == it->first) end = std::min(end, stop_.point);
    const std::size_t take = std::min(max_points - n, end - next_.point);
    const auto first = k.p_base_mm.begin() + static_cast<std::ptrdiff_t>(next_.point);
    out.push_back(
        {it->first, {first, first + static_cast<std::ptrdiff_t>(take)}, Pose2(k.x, k.y, k.theta)});
    n += take;
    next_.point += take;
    settle();
  }
  return out;
}

}  // namespace traverse::mapper
