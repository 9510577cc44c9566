//! Sliding GNSS outages for the differential drive: each outage starts from
//! the alignment of the preceding dead-reckoned stretch to its fixes.

use super::{align, at, DiffDriveDrive, N_PARAMS};
use crate::kinematics::evaluate::{KinematicOutages, KinematicWindow};
use crate::Error;

/// Dead reckons through outages of `outage_s` every `step_s`, the first
/// starting `align_s` after the first sample; each starts from the rigid
/// alignment of the dead-reckoned antenna over the preceding `align_s` to the
/// fixes there, and is scored against the last fix at or before its end.
pub fn evaluate_diff_drive(
    d: &DiffDriveDrive,
    params: &[f64],
    outage_s: f64,
    step_s: f64,
    align_s: f64,
) -> Result<KinematicOutages, Error> {
    let finite = [outage_s, step_s, align_s].iter().all(|v| v.is_finite());
    if !finite || outage_s <= 0.0 || step_s <= 0.0 || align_s <= 0.0 {
        return Err(Error::InvalidParams(format!(
            "outage, step and alignment lengths must be positive, got {outage_s}, {step_s}, {align_s}"
        )));
    }
    if params.len() != N_PARAMS || params.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidParams(format!(
            "{N_PARAMS} finite parameters expected"
        )));
    }
    let (Some(first), Some(last)) = (d.samples.first(), d.samples.last()) else {
        return Err(Error::Insufficient("no odometry samples".into()));
    };
    let mut windows = Vec::new();
    let mut ts = first.t_s + align_s;
    while ts + outage_s <= last.t_s {
        let t_a = ts - align_s;
        let a = d.samples.partition_point(|s| s.t_s < t_a);
        let b = d
            .samples
            .partition_point(|s| s.t_s <= ts + outage_s)
            .saturating_sub(1);
        let fa = d.fixes.partition_point(|f| f.0 < d.samples[a].t_s);
        let fm = d.fixes.partition_point(|f| f.0 <= ts);
        let fe = d.fixes.partition_point(|f| f.0 <= ts + outage_s);
        let start_s = ts;
        ts += step_s;
        if b <= a || fm < fa + 2 || fe <= fm {
            continue;
        }
        let tr = d.local_track(params, a, b, false);
        let p: Vec<[f64; 2]> = d.fixes[fa..fm].iter().map(|f| at(&tr, f.0).0).collect();
        let q: Vec<[f64; 2]> = d.fixes[fa..fm].iter().map(|f| [f.1, f.2]).collect();
        let Some((th, t)) = align(&p, &q) else {
            continue;
        };
        let (s, c) = th.sin_cos();
        let (tf, fx, fy) = d.fixes[fe - 1];
        let e = at(&tr, tf).0;
        let (ex, ey) = (t[0] + c * e[0] - s * e[1], t[1] + s * e[0] + c * e[1]);
        let i0 = d.samples.partition_point(|s| s.t_s < start_s);
        let path_m = (i0 + 1..=b)
            .map(|k| {
                0.5 * (d.samples[k - 1].v_mps + d.samples[k].v_mps).abs()
                    * (d.samples[k].t_s - d.samples[k - 1].t_s)
            })
            .sum();
        windows.push(KinematicWindow {
            start_s,
            end_s: tf,
            path_m,
            final_error_m: (ex - fx).hypot(ey - fy),
        });
    }
    if windows.is_empty() {
        return Err(Error::Insufficient(format!(
            "no {outage_s} s outage with {align_s} s of fixes before it fits in the drive"
        )));
    }
    Ok(KinematicOutages {
        outage_s,
        step_s,
        windows,
    })
}
