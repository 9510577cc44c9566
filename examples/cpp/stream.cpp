// deadreckon's C++ wrapper on a stream of events: the C++ counterpart of
// `deadreckon stream` (docs/c-api.md). Reads event lines (docs/events.md) on
// standard input, hands each to the filter as it is (Filter::push_line: the
// library parses it), and prints one JSON line per pose with the fields and
// values `deadreckon stream` prints.
//
//   stream_cpp [--learn] [--timing wheel|each] [--restore-at N] VEHICLE_TOML [PARAMS_TOML] < events.jsonl
//
// --restore-at N saves the state after N lines and goes on with a filter
// restored from the bytes (as a vehicle resumes after a restart).
//
// Build from the repository root (after cargo build --release -p deadreckon-ffi):
//   c++ -std=c++17 -O2 -I crates/deadreckon-ffi/include examples/cpp/stream.cpp
//   target/release/libdeadreckon_ffi.a -lm -lpthread -ldl -o stream_cpp
// (one line)
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>

#include "deadreckon.hpp"

namespace {

// One pose as `deadreckon stream` prints it (%.17g: every bit).
void print(const deadreckon::BoundedPose& b) {
  const deadreckon::Pose& p = b.pose;
  std::printf(
      "{\"t_s\":%.17g,\"east_m\":%.17g,\"north_m\":%.17g,\"yaw_rad\":%.17g,"
      "\"speed_mps\":%.17g,\"yaw_rate_rps\":%.17g,\"cov_pose\":[",
      p.t_s, p.east_m, p.north_m, p.yaw_rad, p.speed_mps, p.yaw_rate_rps);
  for (int i = 0; i < 9; i++) std::printf(i ? ",%.17g" : "%.17g", p.cov_pose[i]);
  std::printf("],\"bound_95_m\":%.17g}\n", b.bound_95_m);
}

int usage(const char* program) {
  std::cerr << "usage: " << program
            << " [--learn] [--timing wheel|each] [--restore-at N] VEHICLE_TOML [PARAMS_TOML]"
               " < events.jsonl\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  deadreckon::Options options;
  long restore_at = -1;
  int i = 1;
  for (; i < argc && std::string_view(argv[i]).substr(0, 2) == "--"; i++) {
    std::string_view a = argv[i];
    if (a == "--learn") {
      options.learn = true;
    } else if (a == "--timing" && i + 1 < argc) {
      options.timing = std::string_view(argv[++i]) == "each" ? deadreckon::Timing::each
                                                              : deadreckon::Timing::wheel;
    } else if (a == "--restore-at" && i + 1 < argc) {
      restore_at = std::atol(argv[++i]);
    } else {
      return usage(argv[0]);
    }
  }
  if (argc - i < 1 || argc - i > 2) return usage(argv[0]);
  try {
    std::optional<std::string> params;
    if (argc - i == 2) params = argv[i + 1];
    auto filter = deadreckon::Filter::from_files(argv[i], params, options);
    if (auto w = filter.warning()) std::cerr << "warning: " << *w << "\n";
    std::string line;
    long line_no = 0;
    while (std::getline(std::cin, line)) {
      line_no++;
      filter.push_line(line);
      for (const auto& p : filter.take_poses_with_bounds()) print(p);
      if (line_no == restore_at) filter = deadreckon::Filter::restore(filter.save());
    }
    filter.finish();
    for (const auto& p : filter.take_poses_with_bounds()) print(p);
    if (auto l = filter.learned()) {
      std::fprintf(stderr, "learned: %.0f%% calibrated, %s\n", l->calibrated_pct,
                   l->valid ? "valid" : "not yet valid");
    }
  } catch (const deadreckon::Error& e) {
    std::cerr << "stream_cpp: " << e.what() << " (status " << e.status() << ")\n";
    return 1;
  }
  return 0;
}
