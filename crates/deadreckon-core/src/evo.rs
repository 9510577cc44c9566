//! Trajectory errors as `evo` computes them, so our numbers and `evo_ape` /
//! `evo_rpe` on the files `deadreckon run` writes (TUM, KITTI) agree.
//!
//! Matched to evo 1.38.1 (`evo/core/sync.py`, `evo/core/filters.py`,
//! `evo/core/metrics.py`, `evo/main_rpe.py`), with evo's defaults:
//!
//! - **Association** (`associate_trajectories`, `--sync_method nearest_time`,
//!   `--t_max_diff 0.01`, no offset): the trajectory with fewer poses (the
//!   estimate when both have as many) is walked in order; each of its stamps is
//!   paired with the nearest stamp of the other, the earlier one on a tie,
//!   when they are at most `max_diff_s` apart. A stamp of the longer
//!   trajectory may be used twice.
//! - **Pairs by path** (`filter_pairs_by_path`, `--delta 100 --delta_unit m`,
//!   consecutive pairs): the first associated pose, then every pose where the
//!   path travelled since the last chosen one reaches `delta_m`; consecutive
//!   chosen poses form the pairs. The path is measured on the **estimate** by
//!   default, as `evo_rpe` does (`--pairs_from_reference` measures it on the
//!   reference).
//! - **Relative pose error, translation part**: for a pair (i, j),
//!   E = (Q_i⁻¹ Q_j)⁻¹ (P_i⁻¹ P_j) with Q the reference and P the estimate, and
//!   the error is ‖translation(E)‖, in metres: how far the estimate's motion
//!   over about `delta_m` of path, seen from its own start pose, misses the
//!   reference's.
//! - **Absolute pose error, translation part** (`evo_ape`, no alignment): the
//!   distance between associated positions.
//! - Statistics as `evo` reports them: rmse, mean, median, std (population),
//!   min, max, sse.
//!
//! Poses are planar here (z = 0, no roll or pitch), as they are in the files.

use crate::{Error, Need, Rule, Track, TrackPoint};

/// The evo release these functions are matched to.
pub const EVO_VERSION: &str = "1.38.1";

/// evo's default `--t_max_diff`, s.
pub const DEFAULT_MAX_DIFF_S: f64 = 0.01;

/// Decimals of the timestamps in the TUM and KITTI files (nanoseconds).
pub const TIME_DECIMALS: usize = 9;
/// Decimals of the positions in the TUM and KITTI files (micrometres).
pub const POSITION_DECIMALS: usize = 6;
/// Decimals of quaternion and rotation-matrix entries in the files.
pub const ROTATION_DECIMALS: usize = 9;

fn round_as_written(v: f64, decimals: usize) -> f64 {
    // The nearest double to the decimal text, as a reader parses it.
    format!("{v:.decimals$}").parse().unwrap_or(v)
}

/// `track` with its times and positions rounded as the TUM and KITTI writers
/// print them, so a metric computed on it sees what evo reads from the files
/// (a path of simulated 0.1 m steps reaches exactly 100 m, and which pose
/// completes a pair can hang on the last digit).
pub fn as_written(track: &Track) -> Track {
    Track {
        name: track.name.clone(),
        points: track
            .points
            .iter()
            .map(|p| TrackPoint {
                t_s: round_as_written(p.t_s, TIME_DECIMALS),
                east_m: round_as_written(p.east_m, POSITION_DECIMALS),
                north_m: round_as_written(p.north_m, POSITION_DECIMALS),
                ..*p
            })
            .collect(),
        origin: track.origin,
    }
}

/// Which trajectory's travelled path chooses the pose pairs of the RPE.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PairsFrom {
    /// The estimate's path (evo's default).
    #[default]
    Estimate,
    /// The reference's path (`evo_rpe --pairs_from_reference`).
    Reference,
}

/// Options of [`rpe`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RpeOptions {
    /// Path length between the poses of a pair, m (`--delta`, `--delta_unit m`).
    pub delta_m: f64,
    /// Largest time difference of associated poses, s (`--t_max_diff`).
    pub max_diff_s: f64,
    /// Whose path chooses the pairs.
    pub pairs_from: PairsFrom,
}

impl Default for RpeOptions {
    fn default() -> Self {
        RpeOptions {
            delta_m: 100.0,
            max_diff_s: DEFAULT_MAX_DIFF_S,
            pairs_from: PairsFrom::Estimate,
        }
    }
}

/// The statistics evo prints and saves, over the errors of one metric.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Stats {
    /// Root mean square, m.
    pub rmse: f64,
    /// Mean, m.
    pub mean: f64,
    /// Median (mean of the two middle values for an even count), m.
    pub median: f64,
    /// Population standard deviation, m.
    pub std: f64,
    /// Smallest, m.
    pub min: f64,
    /// Largest, m.
    pub max: f64,
    /// Sum of squares, m².
    pub sse: f64,
}

impl Stats {
    /// The statistics of `errors` (`None` when empty).
    pub fn of(errors: &[f64]) -> Option<Stats> {
        if errors.is_empty() {
            return None;
        }
        let n = errors.len() as f64;
        let sse: f64 = errors.iter().map(|e| e * e).sum();
        let mean = errors.iter().sum::<f64>() / n;
        let var = errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / n;
        let mut sorted = errors.to_vec();
        sorted.sort_by(f64::total_cmp);
        let m = sorted.len() / 2;
        let median = if sorted.len() % 2 == 1 {
            sorted[m]
        } else {
            0.5 * (sorted[m - 1] + sorted[m])
        };
        Some(Stats {
            rmse: (sse / n).sqrt(),
            mean,
            median,
            std: var.sqrt(),
            min: sorted[0],
            max: sorted[sorted.len() - 1],
            sse,
        })
    }
}

/// The errors of one metric between a reference and an estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryError {
    /// Poses associated in time.
    pub matched: usize,
    /// For each error: the estimate's time at its (end) pose, s.
    pub t_s: Vec<f64>,
    /// The errors, m.
    pub errors_m: Vec<f64>,
    /// Their statistics.
    pub stats: Stats,
}

/// evo's association of two sorted or unsorted stamp lists: the pairs
/// `(index in reference, index in estimate)` in the order evo keeps them.
pub fn associate(reference_t: &[f64], estimate_t: &[f64], max_diff_s: f64) -> Vec<(usize, usize)> {
    // `second_longer`: the estimate (evo's second trajectory) has more poses.
    let second_longer = estimate_t.len() > reference_t.len();
    let (short, long) = if second_longer {
        (reference_t, estimate_t)
    } else {
        (estimate_t, reference_t)
    };
    let matches = matching_time_indices(short, long, max_diff_s);
    matches
        .into_iter()
        .map(|(s, l)| if second_longer { (s, l) } else { (l, s) })
        .collect()
}

/// `matching_time_indices`: for each stamp of `stamps_1`, the nearest stamp of
/// `stamps_2` within `max_diff` (binary search on sorted `stamps_2`, a linear
/// search with the first minimum otherwise).
fn matching_time_indices(stamps_1: &[f64], stamps_2: &[f64], max_diff: f64) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    if stamps_2.is_empty() {
        return out;
    }
    let sorted = stamps_2.windows(2).all(|w| w[1] - w[0] >= 0.0);
    if !sorted {
        for (i1, &s1) in stamps_1.iter().enumerate() {
            let mut best = 0;
            for (i2, &s2) in stamps_2.iter().enumerate() {
                if (s2 - s1).abs() < (stamps_2[best] - s1).abs() {
                    best = i2;
                }
            }
            if (stamps_2[best] - s1).abs() <= max_diff {
                out.push((i1, best));
            }
        }
        return out;
    }
    let n = stamps_2.len();
    for (i1, &s1) in stamps_1.iter().enumerate() {
        if s1 < stamps_2[0] - max_diff || s1 > stamps_2[n - 1] + max_diff {
            continue;
        }
        // numpy.searchsorted(side="right"): the first index with a larger stamp.
        let idx = stamps_2.partition_point(|&s| s <= s1).min(n - 1);
        let diff_ub = stamps_2[idx] - s1;
        let diff_lb = if idx > 0 {
            s1 - stamps_2[idx - 1]
        } else {
            f64::INFINITY
        };
        let best = if diff_ub <= max_diff && diff_ub < diff_lb {
            idx
        } else if diff_lb <= max_diff && diff_lb <= diff_ub {
            idx - 1
        } else {
            continue;
        };
        out.push((i1, best));
    }
    out
}

/// `filter_pairs_by_path` (consecutive pairs): indices into `points` of the
/// pose pairs about `delta_m` of travelled path apart.
pub fn pairs_by_path(points: &[&TrackPoint], delta_m: f64) -> Vec<(usize, usize)> {
    let mut ids = vec![0usize];
    let Some(first) = points.first() else {
        return Vec::new();
    };
    let mut previous = *first;
    let mut path = 0.0;
    for (i, p) in points.iter().enumerate().skip(1) {
        let (dx, dy) = (p.east_m - previous.east_m, p.north_m - previous.north_m);
        path += (dx * dx + dy * dy).sqrt();
        previous = p;
        if path >= delta_m {
            ids.push(i);
            path = 0.0;
        }
    }
    ids.windows(2).map(|w| (w[0], w[1])).collect()
}

/// The motion from `a` to `b` in `a`'s frame: (forward, left) in metres.
fn relative_translation(a: &TrackPoint, b: &TrackPoint) -> (f64, f64) {
    let (dx, dy) = (b.east_m - a.east_m, b.north_m - a.north_m);
    let (s, c) = a.yaw_rad.sin_cos();
    (c * dx + s * dy, -s * dx + c * dy)
}

/// The poses of both tracks evo associates, as (reference, estimate) pairs.
fn associated<'a>(
    reference: &'a Track,
    estimate: &'a Track,
    max_diff_s: f64,
) -> Result<Vec<(&'a TrackPoint, &'a TrackPoint)>, Error> {
    let rt: Vec<f64> = reference.points.iter().map(|p| p.t_s).collect();
    let et: Vec<f64> = estimate.points.iter().map(|p| p.t_s).collect();
    let pairs = associate(&rt, &et, max_diff_s);
    if pairs.is_empty() {
        return Err(Need::Association {
            reference: reference.name.clone(),
            estimate: estimate.name.clone(),
            max_diff_s,
        }
        .into());
    }
    Ok(pairs
        .into_iter()
        .map(|(r, e)| (&reference.points[r], &estimate.points[e]))
        .collect())
}

/// The relative pose error (translation part) of `estimate` against
/// `reference`, as `evo_rpe tum REF EST --delta D --delta_unit m` reports it.
pub fn rpe(
    reference: &Track,
    estimate: &Track,
    opts: &RpeOptions,
) -> Result<TrajectoryError, Error> {
    if !(opts.delta_m > 0.0 && opts.delta_m.is_finite()) {
        return Err(Error::param("RPE delta_m", opts.delta_m, Rule::Positive));
    }
    let poses = associated(reference, estimate, opts.max_diff_s)?;
    let chooser: Vec<&TrackPoint> = poses
        .iter()
        .map(|(r, e)| match opts.pairs_from {
            PairsFrom::Estimate => *e,
            PairsFrom::Reference => *r,
        })
        .collect();
    let pairs = pairs_by_path(&chooser, opts.delta_m);
    if pairs.is_empty() {
        let mut path = 0.0;
        for w in chooser.windows(2) {
            path += (w[1].east_m - w[0].east_m).hypot(w[1].north_m - w[0].north_m);
        }
        return Err(Need::RpePath {
            whose: match opts.pairs_from {
                PairsFrom::Estimate => "estimate's",
                PairsFrom::Reference => "reference's",
            },
            poses: poses.len(),
            path_m: path,
            delta_m: opts.delta_m,
        }
        .into());
    }
    let mut errors_m = Vec::with_capacity(pairs.len());
    let mut t_s = Vec::with_capacity(pairs.len());
    for (i, j) in pairs {
        // E = (Q_i⁻¹ Q_j)⁻¹ (P_i⁻¹ P_j): its translation is the difference of
        // the two relative translations, turned by the reference's relative
        // rotation, which keeps its length.
        let q = relative_translation(poses[i].0, poses[j].0);
        let p = relative_translation(poses[i].1, poses[j].1);
        errors_m.push((p.0 - q.0).hypot(p.1 - q.1));
        t_s.push(poses[j].1.t_s);
    }
    finish(poses.len(), t_s, errors_m)
}

/// The absolute pose error (translation part, no alignment) of `estimate`
/// against `reference`, as `evo_ape tum REF EST` reports it.
pub fn ape(reference: &Track, estimate: &Track, max_diff_s: f64) -> Result<TrajectoryError, Error> {
    let poses = associated(reference, estimate, max_diff_s)?;
    let errors_m = poses
        .iter()
        .map(|(r, e)| (e.east_m - r.east_m).hypot(e.north_m - r.north_m))
        .collect();
    let t_s = poses.iter().map(|(_, e)| e.t_s).collect();
    finish(poses.len(), t_s, errors_m)
}

fn finish(matched: usize, t_s: Vec<f64>, errors_m: Vec<f64>) -> Result<TrajectoryError, Error> {
    if let Some(bad) = errors_m.iter().position(|e: &f64| !e.is_finite()) {
        return Err(Error::Numerical {
            t_s: t_s[bad],
            what: "non-finite pose in a trajectory error".into(),
        });
    }
    let stats = Stats::of(&errors_m).ok_or(Error::Insufficient {
        need: Need::TrajectoryErrors,
    })?;
    Ok(TrajectoryError {
        matched,
        t_s,
        errors_m,
        stats,
    })
}

/// The poses of `track` that evo's association pairs with `with` (in the
/// association's order, a pose repeated where evo uses it twice), so that two
/// KITTI files, which carry no timestamps, line up pose for pose: write one
/// track synced with the other, and the other synced with the first. With as
/// many poses in both, `with` plays evo's reference.
pub fn synced(track: &Track, with: &Track, max_diff_s: f64) -> Result<Track, Error> {
    let poses = associated(with, track, max_diff_s)?;
    Ok(Track {
        name: track.name.clone(),
        points: poses.into_iter().map(|(_, p)| *p).collect(),
        origin: track.origin,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(t_s: f64, e: f64, n: f64, yaw: f64) -> TrackPoint {
        TrackPoint {
            t_s,
            east_m: e,
            north_m: n,
            yaw_rad: yaw,
            speed_mps: 0.0,
            yaw_rate_rps: 0.0,
            cov_pose: [0.0; 9],
        }
    }

    fn track(name: &str, points: Vec<TrackPoint>) -> Track {
        Track {
            name: name.into(),
            points,
            origin: None,
        }
    }

    #[test]
    fn association_walks_the_shorter_and_breaks_ties_to_the_earlier() {
        // Reference every 0.05 s, estimate every 0.0125 s, 3 ms later: the
        // reference is shorter, so each of its stamps finds the nearest
        // estimate stamp.
        let rt: Vec<f64> = (0..5).map(|k| k as f64 * 0.05).collect();
        let et: Vec<f64> = (0..20).map(|k| k as f64 * 0.0125 + 0.003).collect();
        let pairs = associate(&rt, &et, 0.01);
        assert_eq!(pairs, [(0, 0), (1, 4), (2, 8), (3, 12), (4, 16)]);
        // A stamp exactly between two: the earlier one (numpy's first minimum).
        assert_eq!(
            associate(&[1.0, 2.0], &[0.5, 1.5, 2.5], 0.5),
            [(0, 0), (1, 1)]
        );
        // Beyond max_diff: no pair; equal lengths: the estimate is walked.
        assert_eq!(associate(&[0.0, 1.0], &[0.02, 1.005], 0.01), [(1, 1)]);
        // Unsorted stamps fall back to the linear search.
        assert_eq!(
            associate(&[2.0, 0.0, 1.0], &[0.0, 1.0], 0.01),
            [(1, 0), (2, 1)]
        );
    }

    #[test]
    fn pairs_start_at_the_first_pose_and_restart_the_path() {
        let pts: Vec<TrackPoint> = (0..=30)
            .map(|k| pt(k as f64, 10.0 * k as f64, 0.0, 0.0))
            .collect();
        let refs: Vec<&TrackPoint> = pts.iter().collect();
        // 10 m steps, delta 100 m: poses 0, 10, 20, 30.
        assert_eq!(pairs_by_path(&refs, 100.0), [(0, 10), (10, 20), (20, 30)]);
        // delta 95 m: still every 10th pose (the path restarts at 0 at a chosen pose).
        assert_eq!(pairs_by_path(&refs, 95.0), [(0, 10), (10, 20), (20, 30)]);
        assert!(pairs_by_path(&refs, 400.0).is_empty());
    }

    #[test]
    fn rpe_of_a_scaled_estimate_is_the_scale_error_and_ignores_a_rigid_offset() {
        // Reference: a 300 m straight line east at 1 m per pose. Estimate: 1%
        // too long, rotated by 0.3 rad and shifted (a rigid transform of its
        // own): the RPE per 100 m is 1 m on every pair.
        let reference = track(
            "truth",
            (0..=300)
                .map(|k| pt(k as f64, k as f64, 0.0, 0.0))
                .collect(),
        );
        let (s, c) = 0.3f64.sin_cos();
        let estimate = track(
            "dr",
            (0..=300)
                .map(|k| {
                    let d = 1.01 * k as f64;
                    pt(k as f64, 5.0 + c * d, -2.0 + s * d, 0.3)
                })
                .collect(),
        );
        let r = rpe(
            &reference,
            &estimate,
            &RpeOptions {
                pairs_from: PairsFrom::Reference,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(r.matched, 301);
        assert_eq!(r.errors_m.len(), 3);
        for e in &r.errors_m {
            assert!((e - 1.0).abs() < 1e-9, "{e}");
        }
        // From the estimate's path (1.01 m per pose) the pairs are 100 poses
        // apart too (99 poses are 99.99 m): the same errors.
        let r = rpe(&reference, &estimate, &RpeOptions::default()).unwrap();
        assert_eq!(r.t_s, [100.0, 200.0, 300.0]);
        assert!((r.stats.rmse - 1.0).abs() < 1e-9);
        // A heading error at a pair's start swings the whole segment.
        let bent = track(
            "bent",
            reference
                .points
                .iter()
                .map(|p| TrackPoint {
                    yaw_rad: if p.t_s == 100.0 { 0.01 } else { 0.0 },
                    ..*p
                })
                .collect(),
        );
        let r = rpe(&reference, &bent, &RpeOptions::default()).unwrap();
        let expected = 2.0 * 100.0 * (0.005f64).sin();
        assert!((r.errors_m[1] - expected).abs() < 1e-9 && r.errors_m[0] == 0.0);
    }

    #[test]
    fn stats_as_numpy_computes_them() {
        let s = Stats::of(&[3.0, 1.0, 4.0, 2.0]).unwrap();
        assert_eq!((s.median, s.min, s.max, s.sse), (2.5, 1.0, 4.0, 30.0));
        assert!((s.rmse - 7.5f64.sqrt()).abs() < 1e-15);
        assert!((s.std - 1.25f64.sqrt()).abs() < 1e-15);
        assert!(Stats::of(&[]).is_none());
    }

    #[test]
    fn too_short_a_path_or_no_common_time_is_an_error() {
        let a = track(
            "a",
            (0..10).map(|k| pt(k as f64, k as f64, 0.0, 0.0)).collect(),
        );
        let b = track(
            "b",
            (0..10)
                .map(|k| pt(100.0 + k as f64, 0.0, 0.0, 0.0))
                .collect(),
        );
        let e = rpe(&a, &a, &RpeOptions::default()).unwrap_err().to_string();
        assert!(e.contains("9.0 m") && e.contains("100 m"), "{e}");
        let e = ape(&a, &b, 0.01).unwrap_err().to_string();
        assert!(e.contains("`a` and `b`"), "{e}");
        let s = synced(&b, &a, 0.01);
        assert!(s.is_err());
    }
}
