// deadreckon's C++17 wrapper over the C API (deadreckon.h), header-only:
// an RAII filter handle, exceptions carrying the status and the message,
// std::string_view in, values out (nothing for the caller to free).
// Guide: docs/c-api.md.
//
//   deadreckon::Filter f = deadreckon::Filter::from_files("vehicle.toml");
//   f.push_line(R"({"t_s":0.1,"sensor":"yaw_rate","yaw_rate_rps":0.01})");
//   while (auto pose = f.next_pose()) { use(pose->east_m, pose->north_m); }
//
// A Filter is used by one thread at a time (it may move between threads).
#ifndef DEADRECKON_HPP
#define DEADRECKON_HPP

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "deadreckon.h"

namespace deadreckon {

// A failed call: the C API's status and its message (dr_last_error).
class Error : public std::runtime_error {
 public:
  Error(DrStatus status, const std::string& message)
      : std::runtime_error(message), status_(status) {}
  // DR_STATUS_NOT_FINITE, DR_STATUS_TIME_BACKWARDS, ... (deadreckon.h).
  DrStatus status() const noexcept { return status_; }

 private:
  DrStatus status_;
};

namespace detail {
inline void check(DrStatus s) {
  if (s != DR_STATUS_OK) throw Error(s, dr_last_error());
}
// string_view::data() may be null for an empty view; the C API wants a pointer.
inline const char* data(std::string_view s) { return s.data() ? s.data() : ""; }
}  // namespace detail

// The filter's timing scheme (stream --timing).
enum class Timing : std::int32_t {
  wheel = DR_TIMING_WHEEL,  // one epoch per wheel row (the paper's)
  each = DR_TIMING_EACH,    // one epoch per reading
};

// The options of `deadreckon stream`.
struct Options {
  Timing timing = Timing::wheel;
  bool learn = false;  // learn the six parameters (stream --learn)
};

using Pose = DrPose;              // t_s, east_m, north_m, yaw_rad, speed_mps, yaw_rate_rps, cov_pose[9]
using Params = DrParams;          // the six parameters (or their standard errors)
using Learned = DrLearned;        // params, std, valid, calibrated_pct
using GateCounts = DrGateCounts;  // accepted/rejected/recovered[DrGateSensor]

// A pose with its 95 % error bound, m (docs/bound.md).
struct BoundedPose {
  Pose pose;
  double bound_95_m;
};

// The online filter of `deadreckon stream`; see docs/c-api.md.
class Filter {
 public:
  // From the text of a vehicle.toml and optionally of a params.toml
  // (without: the vehicle's nominal parameters).
  static Filter from_text(std::string_view vehicle_toml,
                          std::optional<std::string_view> params_toml = std::nullopt,
                          Options options = {}) {
    DrOptions o = to_c(options);
    DrFilter* f = nullptr;
    detail::check(dr_filter_new(detail::data(vehicle_toml), vehicle_toml.size(),
                                params_toml ? detail::data(*params_toml) : nullptr,
                                params_toml ? params_toml->size() : 0, &o, &f));
    return Filter(f);
  }

  // From a vehicle.toml and optionally a params.toml file, read as
  // `deadreckon stream --vehicle V --params P` reads them.
  static Filter from_files(const std::string& vehicle_path,
                           const std::optional<std::string>& params_path = std::nullopt,
                           Options options = {}) {
    DrOptions o = to_c(options);
    DrFilter* f = nullptr;
    detail::check(dr_filter_new_from_files(vehicle_path.c_str(),
                                           params_path ? params_path->c_str() : nullptr, &o, &f));
    return Filter(f);
  }

  // From the bytes save() returned (or a `stream --state` file's).
  static Filter restore(const std::uint8_t* bytes, std::size_t len) {
    DrFilter* f = nullptr;
    detail::check(dr_filter_restore(bytes, len, &f));
    return Filter(f);
  }
  static Filter restore(const std::vector<std::uint8_t>& state) {
    return restore(state.data(), state.size());
  }

  Filter(const Filter&) = delete;
  Filter& operator=(const Filter&) = delete;
  Filter(Filter&& other) noexcept : f_(std::exchange(other.f_, nullptr)) {}
  Filter& operator=(Filter&& other) noexcept {
    if (this != &other) {
      dr_filter_free(f_);
      f_ = std::exchange(other.f_, nullptr);
    }
    return *this;
  }
  ~Filter() { dr_filter_free(f_); }

  // One event per sensor (time order; see deadreckon.h for units).
  void push_wheel_ticks(double t_s, std::int64_t fl, std::int64_t fr, std::int64_t rl,
                        std::int64_t rr) {
    detail::check(dr_push_wheel_ticks(f_, t_s, fl, fr, rl, rr));
  }
  void push_wheel_speeds(double t_s, double fl_mps, double fr_mps, double rl_mps,
                         double rr_mps) {
    detail::check(dr_push_wheel_speeds(f_, t_s, fl_mps, fr_mps, rl_mps, rr_mps));
  }
  void push_yaw_rate(double t_s, double yaw_rate_rps) {
    detail::check(dr_push_yaw_rate(f_, t_s, yaw_rate_rps));
  }
  void push_speed(double t_s, double speed_mps) { detail::check(dr_push_speed(f_, t_s, speed_mps)); }
  void push_steering(double t_s, double steering_wheel_rad) {
    detail::check(dr_push_steering(f_, t_s, steering_wheel_rad));
  }
  void push_gnss(double t_s, double east_m, double north_m, double std_m,
                 std::optional<double> course_deg = std::nullopt,
                 std::optional<double> speed_mps = std::nullopt) {
    detail::check(dr_push_gnss(f_, t_s, east_m, north_m, std_m, course_deg ? &*course_deg : nullptr,
                               speed_mps ? &*speed_mps : nullptr));
  }
  // One line of the event schema (docs/events.md), without its newline.
  void push_line(std::string_view line) {
    detail::check(dr_push_line(f_, detail::data(line), line.size()));
  }

  // The oldest pose not yet taken (one per filter epoch), if any.
  std::optional<Pose> next_pose() {
    Pose p;
    DrStatus s = dr_next_pose(f_, &p);
    if (s == DR_STATUS_NO_POSE) return std::nullopt;
    detail::check(s);
    return p;
  }
  // Every pose not yet taken, oldest first.
  std::vector<Pose> take_poses() {
    std::vector<Pose> out;
    while (auto p = next_pose()) out.push_back(*p);
    return out;
  }
  // The oldest pose not yet taken with its 95 % bound, if any.
  std::optional<BoundedPose> next_pose_with_bound() {
    BoundedPose p;
    DrStatus s = dr_next_pose_with_bound(f_, &p.pose, &p.bound_95_m);
    if (s == DR_STATUS_NO_POSE) return std::nullopt;
    detail::check(s);
    return p;
  }
  // Every pose not yet taken with its bound, oldest first.
  std::vector<BoundedPose> take_poses_with_bounds() {
    std::vector<BoundedPose> out;
    while (auto p = next_pose_with_bound()) out.push_back(*p);
    return out;
  }
  // The newest pose's 95 % bound, none before the first epoch.
  std::optional<double> latest_bound() const {
    double b = 0.0;
    return available(dr_latest_bound(f_, &b)) ? std::optional<double>(b) : std::nullopt;
  }
  // The newest pose, none before the first epoch.
  std::optional<Pose> latest_pose() const {
    Pose p;
    return available(dr_latest_pose(f_, &p)) ? std::optional<Pose>(p) : std::nullopt;
  }
  bool is_started() const {
    bool b = false;
    detail::check(dr_is_started(f_, &b));
    return b;
  }
  // The learned parameters, none unless learning and started.
  std::optional<Learned> learned() const {
    Learned l;
    return available(dr_learned(f_, &l)) ? std::optional<Learned>(l) : std::nullopt;
  }
  // The χ² gate's counts, none before the start.
  std::optional<GateCounts> gate_counts() const {
    GateCounts g;
    return available(dr_gate_counts(f_, &g)) ? std::optional<GateCounts>(g) : std::nullopt;
  }
  // Ends the stream: the epochs still waiting run (their poses queued).
  void finish() { detail::check(dr_finish(f_)); }

  // The whole state as bytes (what `stream --state` writes).
  std::vector<std::uint8_t> save() const {
    std::size_t len = 0;
    DrStatus s = dr_save_state(f_, nullptr, 0, &len);
    if (s != DR_STATUS_BUFFER_TOO_SMALL) detail::check(s);
    std::vector<std::uint8_t> bytes(len);
    detail::check(dr_save_state(f_, bytes.data(), bytes.size(), &len));
    bytes.resize(len);
    return bytes;
  }

  // The params.toml's warning (corrections stream does not apply), if any.
  std::optional<std::string> warning() const {
    const char* w = dr_filter_warning(f_);
    return w ? std::optional<std::string>(w) : std::nullopt;
  }

  // The C handle, for calls this wrapper does not have (still owned here).
  DrFilter* get() noexcept { return f_; }

 private:
  explicit Filter(DrFilter* f) noexcept : f_(f) {}
  static DrOptions to_c(Options o) {
    DrOptions c = dr_default_options();
    c.timing = static_cast<std::int32_t>(o.timing);
    c.learn = o.learn;
    return c;
  }
  // True on DR_STATUS_OK, false on DR_STATUS_NOT_AVAILABLE; throws otherwise.
  static bool available(DrStatus s) {
    if (s == DR_STATUS_NOT_AVAILABLE) return false;
    detail::check(s);
    return true;
  }

  DrFilter* f_;
};

}  // namespace deadreckon

#endif  // DEADRECKON_HPP
