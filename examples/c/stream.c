/* deadreckon's C API on a stream of events: the C counterpart of
 * `deadreckon stream` (docs/c-api.md). Reads event lines (docs/events.md)
 * on standard input, feeds each through the typed push function of its
 * sensor, and prints one JSON line per pose with the fields and values
 * `deadreckon stream` prints.
 *
 *   stream_c [--learn] [--timing wheel|each] [--restore-at N] VEHICLE_TOML [PARAMS_TOML] < events.jsonl
 *
 * --restore-at N saves the state after N lines, frees the filter and goes on
 * with one restored from the bytes (as a vehicle resumes after a restart).
 *
 * Build from the repository root (after cargo build --release -p deadreckon-ffi):
 *   cc -O2 -I crates/deadreckon-ffi/include examples/c/stream.c \
 *      target/release/libdeadreckon_ffi.a -lm -lpthread -ldl -o stream_c
 *
 * Parsing the lines is this example's own business: a few lines of strstr
 * and strtod for the flat objects of the schema, not a JSON parser. */
#define _POSIX_C_SOURCE 200809L
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "deadreckon.h"

/* Prints the failed call's message and exits. */
static void fail(const char *what, DrStatus status) {
    fprintf(stderr, "stream_c: %s: status %d: %s\n", what, (int)status, dr_last_error());
    exit(1);
}

/* Where the value of "key": starts in a flat JSON object, or NULL. */
static const char *value_of(const char *line, const char *key) {
    char pattern[64];
    snprintf(pattern, sizeof pattern, "\"%s\":", key);
    const char *at = strstr(line, pattern);
    return at == NULL ? NULL : at + strlen(pattern);
}

/* The number of "key"; false when absent or not a number. */
static bool number(const char *line, const char *key, double *out) {
    const char *at = value_of(line, key);
    char *end = NULL;
    if (at != NULL) *out = strtod(at, &end);
    return at != NULL && end != at;
}

static bool integer(const char *line, const char *key, int64_t *out) {
    const char *at = value_of(line, key);
    char *end = NULL;
    if (at != NULL) *out = strtoll(at, &end, 10);
    return at != NULL && end != at;
}

static bool is_sensor(const char *line, const char *name) {
    char pattern[64];
    snprintf(pattern, sizeof pattern, "\"sensor\":\"%s\"", name);
    return strstr(line, pattern) != NULL;
}

/* One event line through its typed push function. */
static DrStatus push(DrFilter *f, const char *line, long line_no) {
    double t, a, b, c, d;
    int64_t fl, fr, rl, rr;
    if (!number(line, "t_s", &t)) {
        fprintf(stderr, "stream_c: line %ld: no t_s\n", line_no);
        exit(1);
    }
    if (is_sensor(line, "wheel_ticks") && integer(line, "fl", &fl) && integer(line, "fr", &fr) &&
        integer(line, "rl", &rl) && integer(line, "rr", &rr))
        return dr_push_wheel_ticks(f, t, fl, fr, rl, rr);
    if (is_sensor(line, "wheel_speeds") && number(line, "fl_mps", &a) &&
        number(line, "fr_mps", &b) && number(line, "rl_mps", &c) && number(line, "rr_mps", &d))
        return dr_push_wheel_speeds(f, t, a, b, c, d);
    if (is_sensor(line, "yaw_rate") && number(line, "yaw_rate_rps", &a))
        return dr_push_yaw_rate(f, t, a);
    if (is_sensor(line, "speed") && number(line, "speed_mps", &a)) return dr_push_speed(f, t, a);
    if (is_sensor(line, "steering") && number(line, "steering_wheel_rad", &a))
        return dr_push_steering(f, t, a);
    if (is_sensor(line, "gnss") && number(line, "east_m", &a) && number(line, "north_m", &b) &&
        number(line, "std_m", &c)) {
        double course, speed;
        bool has_course = number(line, "course_deg", &course);
        bool has_speed = number(line, "speed_mps", &speed);
        return dr_push_gnss(f, t, a, b, c, has_course ? &course : NULL, has_speed ? &speed : NULL);
    }
    fprintf(stderr, "stream_c: line %ld: not an event this example reads: %s\n", line_no, line);
    exit(1);
}

/* Prints every pose waiting, as `deadreckon stream` does (%.17g: every bit). */
static void print_poses(DrFilter *f) {
    DrPose p;
    double bound_95_m;
    DrStatus s;
    while ((s = dr_next_pose_with_bound(f, &p, &bound_95_m)) == DR_STATUS_OK) {
        printf("{\"t_s\":%.17g,\"east_m\":%.17g,\"north_m\":%.17g,\"yaw_rad\":%.17g,"
               "\"speed_mps\":%.17g,\"yaw_rate_rps\":%.17g,\"cov_pose\":[",
               p.t_s, p.east_m, p.north_m, p.yaw_rad, p.speed_mps, p.yaw_rate_rps);
        for (int i = 0; i < 9; i++) printf(i ? ",%.17g" : "%.17g", p.cov_pose[i]);
        printf("],\"bound_95_m\":%.17g}\n", bound_95_m);
    }
    if (s != DR_STATUS_NO_POSE) fail("dr_next_pose_with_bound", s);
}

/* Saves the state, frees the filter, returns one restored from the bytes. */
static DrFilter *save_and_restore(DrFilter *f) {
    size_t len = 0;
    DrStatus s = dr_save_state(f, NULL, 0, &len);
    if (s != DR_STATUS_BUFFER_TOO_SMALL) fail("dr_save_state (size)", s);
    uint8_t *bytes = malloc(len);
    if (bytes == NULL) exit(1);
    if ((s = dr_save_state(f, bytes, len, &len)) != DR_STATUS_OK) fail("dr_save_state", s);
    dr_filter_free(f);
    DrFilter *g = NULL;
    if ((s = dr_filter_restore(bytes, len, &g)) != DR_STATUS_OK) fail("dr_filter_restore", s);
    free(bytes);
    return g;
}

int main(int argc, char **argv) {
    DrOptions options = dr_default_options();
    long restore_at = -1;
    int i = 1;
    for (; i < argc && strncmp(argv[i], "--", 2) == 0; i++) {
        if (strcmp(argv[i], "--learn") == 0) {
            options.learn = true;
        } else if (strcmp(argv[i], "--timing") == 0 && i + 1 < argc) {
            i++;
            options.timing = strcmp(argv[i], "each") == 0 ? DR_TIMING_EACH : DR_TIMING_WHEEL;
        } else if (strcmp(argv[i], "--restore-at") == 0 && i + 1 < argc) {
            restore_at = atol(argv[++i]);
        } else {
            break;
        }
    }
    if (argc - i < 1 || argc - i > 2) {
        fprintf(stderr,
                "usage: %s [--learn] [--timing wheel|each] [--restore-at N] VEHICLE_TOML "
                "[PARAMS_TOML] < events.jsonl\n",
                argv[0]);
        return 2;
    }
    DrFilter *f = NULL;
    DrStatus s = dr_filter_new_from_files(argv[i], argc - i == 2 ? argv[i + 1] : NULL, &options, &f);
    if (s != DR_STATUS_OK) fail("dr_filter_new_from_files", s);
    if (dr_filter_warning(f) != NULL) fprintf(stderr, "warning: %s\n", dr_filter_warning(f));

    char *line = NULL;
    size_t cap = 0;
    ssize_t n;
    long line_no = 0;
    while ((n = getline(&line, &cap, stdin)) != -1) {
        line_no++;
        if (n <= 1) continue; /* blank */
        if ((s = push(f, line, line_no)) != DR_STATUS_OK) {
            fprintf(stderr, "stream_c: line %ld: ", line_no);
            fail("push", s);
        }
        print_poses(f);
        if (line_no == restore_at) f = save_and_restore(f);
    }
    free(line);
    if ((s = dr_finish(f)) != DR_STATUS_OK) fail("dr_finish", s);
    print_poses(f);

    DrGateCounts gates;
    if (dr_gate_counts(f, &gates) == DR_STATUS_OK)
        fprintf(stderr, "gnss: %llu accepted, %llu rejected\n",
                (unsigned long long)gates.accepted[DR_GATE_SENSOR_GNSS],
                (unsigned long long)gates.rejected[DR_GATE_SENSOR_GNSS]);
    DrLearned learned;
    if (dr_learned(f, &learned) == DR_STATUS_OK)
        fprintf(stderr, "learned: %.0f%% calibrated, %s\n", learned.calibrated_pct,
                learned.valid ? "valid" : "not yet valid");
    dr_filter_free(f);
    return 0;
}
