//! The fix-error model of the differential drive's GNSS-aided filter
//! (`evaluate --shape diff-drive --start filter`), identified by maximum
//! likelihood of the fixes' innovations on the first half of the Husky bag
//! only: a grid over the wander's standard deviation and time constant and
//! the fixes' white noise, the other noise values at their defaults, the
//! nominal parameters, every fix taken (no gate). The outage errors are not
//! looked at, and nothing of the second half is read.
//!
//! ```sh
//! cargo run --profile ci --example diff_drive_fix_model [-- BAG [UNTIL_S]]
//! ```
//!
//! Prints one line per grid point, best first: mean log-likelihood per fix,
//! wander σ (m), τ (s), white σ (m).

use std::path::Path;

use deadreckon_api::load::Loader;
use deadreckon_core::kinematics::diff_drive::filter::{fix_log_likelihood, FilterNoise};
use deadreckon_core::kinematics::diff_drive::{DiffDriveDrive, YawSource};

/// The first half of the Husky bag: its odometry runs from
/// 1432235498.028 s for 395.3 s on the drive clock.
const FIRST_HALF_UNTIL_S: f64 = 1432235695.7;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let bag = args
        .first()
        .map_or("../shared/data/husky-gps-bag/husky_gps.bag", |s| s.as_str());
    let until = match args.get(1) {
        Some(s) => s.parse()?,
        None => FIRST_HALF_UNTIL_S,
    };
    let drive = Loader::default().drive(Path::new(bag))?;
    let d = DiffDriveDrive::from_drive(&drive, YawSource::Gyro, None, Some(until))?;
    let params = DiffDriveDrive::nominal();
    let mut rows = Vec::new();
    for wander in [1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0] {
        for tau in [30.0, 45.0, 60.0, 90.0, 120.0, 180.0, 300.0, 600.0] {
            for white in [0.01, 0.02, 0.05, 0.1, 0.2, 0.3] {
                let noise = FilterNoise {
                    fix_wander_m: wander,
                    fix_wander_tau_s: tau,
                    fix_white_m: white,
                    ..FilterNoise::default()
                };
                if let Some((ll, n)) = fix_log_likelihood(&d, &params, &noise)? {
                    rows.push((ll, n, wander, tau, white));
                }
            }
        }
    }
    rows.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!("loglik_per_fix  fixes  wander_m  tau_s  white_m");
    for (ll, n, wander, tau, white) in rows {
        println!("{ll:14.4}  {n:5}  {wander:8.2}  {tau:5.0}  {white:7.2}");
    }
    Ok(())
}
