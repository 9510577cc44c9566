/* The C API's bad inputs from C: each is a status and a message, never a
 * crash (run under valgrind by .ci/c-api). Exits 0 when every check holds.
 *
 *   bad_inputs VEHICLE_TOML < events.jsonl
 *
 * The events must start the filter (its GNSS start: the first fix and 10 m
 * of driving), so that the checks after it run on a started filter. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "deadreckon.h"

static int failures = 0;

#define EXPECT(status, want, what)                                                         \
    do {                                                                                   \
        DrStatus got_ = (status);                                                          \
        if (got_ != (want)) {                                                              \
            fprintf(stderr, "FAIL %s: status %d, want %d (%s)\n", what, (int)got_, (int)(want), \
                    dr_last_error());                                                      \
            failures++;                                                                    \
        }                                                                                  \
    } while (0)

#define EXPECT_TRUE(cond, what)                      \
    do {                                             \
        if (!(cond)) {                               \
            fprintf(stderr, "FAIL %s\n", what);      \
            failures++;                              \
        }                                            \
    } while (0)

static DrStatus push_line(DrFilter *f, const char *line) { return dr_push_line(f, line, strlen(line)); }

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s VEHICLE_TOML < events.jsonl\n", argv[0]);
        return 2;
    }
    DrPose pose;
    DrLearned learned;
    DrGateCounts gates;
    bool started = true;
    size_t len = 0;
    double nan = NAN, inf = INFINITY;

    /* Null handles and pointers. */
    EXPECT(dr_push_wheel_ticks(NULL, 1.0, 1, 1, 1, 1), DR_STATUS_NULL_ARGUMENT, "ticks, null handle");
    EXPECT(dr_push_wheel_speeds(NULL, 1.0, 1, 1, 1, 1), DR_STATUS_NULL_ARGUMENT, "speeds, null handle");
    EXPECT(dr_push_yaw_rate(NULL, 1.0, 0.0), DR_STATUS_NULL_ARGUMENT, "gyro, null handle");
    EXPECT(dr_push_speed(NULL, 1.0, 0.0), DR_STATUS_NULL_ARGUMENT, "speed, null handle");
    EXPECT(dr_push_steering(NULL, 1.0, 0.0), DR_STATUS_NULL_ARGUMENT, "steering, null handle");
    EXPECT(dr_push_gnss(NULL, 1.0, 0, 0, 1, NULL, NULL), DR_STATUS_NULL_ARGUMENT, "gnss, null handle");
    EXPECT(push_line(NULL, "{}"), DR_STATUS_NULL_ARGUMENT, "line, null handle");
    EXPECT(dr_next_pose(NULL, &pose), DR_STATUS_NULL_ARGUMENT, "next pose, null handle");
    EXPECT(dr_latest_pose(NULL, &pose), DR_STATUS_NULL_ARGUMENT, "latest pose, null handle");
    EXPECT(dr_learned(NULL, &learned), DR_STATUS_NULL_ARGUMENT, "learned, null handle");
    EXPECT(dr_gate_counts(NULL, &gates), DR_STATUS_NULL_ARGUMENT, "gates, null handle");
    EXPECT(dr_finish(NULL), DR_STATUS_NULL_ARGUMENT, "finish, null handle");
    EXPECT(dr_save_state(NULL, NULL, 0, &len), DR_STATUS_NULL_ARGUMENT, "save, null handle");
    EXPECT_TRUE(strcmp(dr_last_error(), "the filter handle is null") == 0, "the message names the handle");
    EXPECT(dr_filter_free(NULL), DR_STATUS_OK, "free(NULL) does nothing");
    EXPECT(dr_filter_new_from_files(argv[1], NULL, NULL, NULL), DR_STATUS_NULL_ARGUMENT, "new, null out");

    /* Bad configuration: no handle comes back. */
    DrFilter *f = (DrFilter *)&len; /* not null: must be overwritten */
    const char *garbage = "wheelbase_m = [";
    EXPECT(dr_filter_new(garbage, strlen(garbage), NULL, 0, NULL, &f), DR_STATUS_BAD_CONFIG, "TOML garbage");
    EXPECT_TRUE(f == NULL, "no handle on failure");
    EXPECT(dr_filter_new_from_files("/nonexistent/vehicle.toml", NULL, NULL, &f), DR_STATUS_BAD_CONFIG,
           "missing file");
    EXPECT_TRUE(strstr(dr_last_error(), "/nonexistent/vehicle.toml") != NULL, "the message names the file");
    DrOptions bad_timing = dr_default_options();
    bad_timing.timing = 42;
    EXPECT(dr_filter_new_from_files(argv[1], NULL, &bad_timing, &f), DR_STATUS_BAD_CONFIG, "timing 42");
    const uint8_t junk[] = "{\"not\":\"a state\"}";
    EXPECT(dr_filter_restore(junk, sizeof junk - 1, &f), DR_STATUS_BAD_STATE, "junk state");

    /* A filter waiting for its GNSS start. */
    EXPECT(dr_filter_new_from_files(argv[1], NULL, NULL, &f), DR_STATUS_OK, "new");
    EXPECT(dr_is_started(f, &started), DR_STATUS_OK, "is started");
    EXPECT_TRUE(!started, "not started before any event");
    EXPECT(dr_latest_pose(f, &pose), DR_STATUS_NOT_AVAILABLE, "no pose yet");
    EXPECT(dr_learned(f, &learned), DR_STATUS_NOT_AVAILABLE, "not learning");
    EXPECT(dr_gate_counts(f, &gates), DR_STATUS_NOT_AVAILABLE, "no counts yet");
    EXPECT(dr_next_pose(f, &pose), DR_STATUS_NO_POSE, "no pose waiting");
    EXPECT(dr_finish(f), DR_STATUS_FILTER, "finish before the start");

    /* Start it on the events. */
    char *line = NULL;
    size_t cap = 0;
    double last_t = 0.0;
    while (getline(&line, &cap, stdin) != -1) {
        DrStatus s = push_line(f, line);
        if (s != DR_STATUS_OK) {
            fprintf(stderr, "FAIL event line: %s\n", dr_last_error());
            return 1;
        }
        while (dr_next_pose(f, &pose) == DR_STATUS_OK) last_t = pose.t_s;
    }
    free(line);
    EXPECT(dr_is_started(f, &started), DR_STATUS_OK, "is started");
    EXPECT_TRUE(started && last_t > 0.0, "started on the events");
    double t = last_t + 10.0;

    /* NaN and infinite values. */
    EXPECT(dr_push_yaw_rate(f, nan, 0.0), DR_STATUS_NOT_FINITE, "t_s NaN");
    EXPECT(dr_push_speed(f, inf, 1.0), DR_STATUS_NOT_FINITE, "t_s inf");
    EXPECT(dr_push_wheel_speeds(f, t, 1, nan, 1, 1), DR_STATUS_NOT_FINITE, "wheel speed NaN");
    EXPECT(dr_push_yaw_rate(f, t, -inf), DR_STATUS_NOT_FINITE, "gyro -inf");
    EXPECT(dr_push_steering(f, t, nan), DR_STATUS_NOT_FINITE, "steering NaN");
    EXPECT(dr_push_gnss(f, t, nan, 0, 1, NULL, NULL), DR_STATUS_NOT_FINITE, "east NaN");
    EXPECT(dr_push_gnss(f, t, 0, 0, 0, NULL, NULL), DR_STATUS_NOT_FINITE, "std_m 0");
    EXPECT(dr_push_gnss(f, t, 0, 0, 1, &nan, NULL), DR_STATUS_NOT_FINITE, "course NaN");
    EXPECT(dr_push_gnss(f, t, 0, 0, 1, NULL, &inf), DR_STATUS_NOT_FINITE, "gnss speed inf");
    EXPECT_TRUE(strstr(dr_last_error(), "not finite") != NULL, "the message says not finite");

    /* Time going backwards. */
    EXPECT(dr_push_wheel_ticks(f, last_t - 1.0, 1, 1, 1, 1), DR_STATUS_TIME_BACKWARDS, "ticks back in time");
    EXPECT(push_line(f, "{\"t_s\":0.5,\"sensor\":\"yaw_rate\",\"yaw_rate_rps\":0}"), DR_STATUS_TIME_BACKWARDS,
           "line back in time");

    /* Unknown sensors and malformed lines. */
    EXPECT(push_line(f, "{\"t_s\":1e9,\"sensor\":\"lidar\",\"range_m\":3}"), DR_STATUS_UNKNOWN_SENSOR,
           "unknown sensor");
    EXPECT_TRUE(strstr(dr_last_error(), "lidar") != NULL, "the message names the sensor");
    EXPECT(push_line(f, "{not json"), DR_STATUS_BAD_EVENT, "not JSON");
    EXPECT(push_line(f, "{\"t_s\":1e9,\"sensor\":\"speed\"}"), DR_STATUS_BAD_EVENT, "missing value");
    EXPECT(push_line(f, "{\"t_s\":1e9,\"sensor\":\"speed\",\"speed_mps\":1,\"x\":2}"), DR_STATUS_BAD_EVENT,
           "unknown key");
    EXPECT(dr_push_line(f, NULL, 4), DR_STATUS_NULL_ARGUMENT, "null line");
    EXPECT(push_line(f, "   "), DR_STATUS_OK, "a blank line is skipped");

    /* Null outputs on a live handle; a buffer too small. */
    EXPECT(dr_next_pose(f, NULL), DR_STATUS_NULL_ARGUMENT, "next pose, null out");
    EXPECT(dr_latest_pose(f, NULL), DR_STATUS_NULL_ARGUMENT, "latest pose, null out");
    EXPECT(dr_save_state(f, NULL, 0, NULL), DR_STATUS_NULL_ARGUMENT, "save, null len");
    EXPECT(dr_save_state(f, NULL, 0, &len), DR_STATUS_BUFFER_TOO_SMALL, "save, size");
    uint8_t small[16];
    size_t need = len;
    EXPECT(dr_save_state(f, small, sizeof small, &len), DR_STATUS_BUFFER_TOO_SMALL, "save, small buffer");
    EXPECT_TRUE(len == need && need > sizeof small, "the size needed is told");

    /* After all that, the filter still runs and round-trips its state. */
    EXPECT(dr_push_yaw_rate(f, t, 0.0), DR_STATUS_OK, "a good event after the bad ones");
    EXPECT(dr_latest_pose(f, &pose), DR_STATUS_OK, "latest pose");
    EXPECT(dr_gate_counts(f, &gates), DR_STATUS_OK, "gate counts");
    EXPECT_TRUE(gates.accepted[DR_GATE_SENSOR_GNSS] > 0, "GNSS fixes accepted");
    EXPECT(dr_save_state(f, NULL, 0, &need), DR_STATUS_BUFFER_TOO_SMALL, "save, size again");
    uint8_t *bytes = malloc(need);
    EXPECT(dr_save_state(f, bytes, need, &len), DR_STATUS_OK, "save");
    DrFilter *g = NULL;
    EXPECT(dr_filter_restore(bytes, len, &g), DR_STATUS_OK, "restore");
    free(bytes);
    EXPECT(dr_push_wheel_ticks(g, last_t - 1.0, 1, 1, 1, 1), DR_STATUS_TIME_BACKWARDS,
           "back in time right after a restore");
    EXPECT(dr_finish(g), DR_STATUS_OK, "finish the restored filter");
    EXPECT(dr_filter_free(g), DR_STATUS_OK, "free the restored filter");
    EXPECT(dr_filter_free(f), DR_STATUS_OK, "free");

    if (failures) {
        fprintf(stderr, "bad_inputs: %d checks failed\n", failures);
        return 1;
    }
    printf("bad_inputs: every check holds\n");
    return 0;
}
