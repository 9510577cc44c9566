//! Tests of the joint calibration and the refit guard.

use super::*;
use crate::input::{drive_input, Event};

/// A machine trained on the built-in `tedris-car` drive (seed 1), the
/// joint calibration on.
fn trained() -> Tedris {
    let sc = deadreckon_sim::Scenario::builtin("tedris-car").expect("scenario");
    let drive = deadreckon_sim::simulate(&sc, 1).expect("drive").drive;
    let input = drive_input(&drive, None, &[]).expect("input");
    let mut m = Tedris::new(TedrisConfig::default(), input.geometry).expect("machine");
    for e in &input.events {
        let _ = match e {
            Event::Wheel(w) => m.push_wheel(*w).map(|_| ()),
            Event::Heading(h) => m.push_heading(*h),
            Event::Fix(f) => m.push_fix(*f),
        };
    }
    let model = m.model.as_ref().expect("trained");
    assert!(model.complete && model.config.joint_calibration());
    m
}

fn betas(m: &TedrisModel) -> Vec<Vec<f64>> {
    m.fits.iter().map(|f| f.global_beta.clone()).collect()
}

/// The installed values carry the last calibration's robust standard
/// errors; a model file written before they existed loads them as not
/// estimated; a negative one is an error naming the key.
#[test]
fn model_files_carry_the_calibrations_standard_errors() {
    let m = trained();
    let model = m.model.as_ref().expect("model");
    let last = m.last_calibration().expect("a calibration was installed");
    let std = last.std_error.as_ref().expect("estimated");
    let j = last
        .names
        .iter()
        .position(|n| n == "dcf_distance")
        .expect("fitted");
    assert_eq!(model.dcf_distance_std_rad_per_m, Some(std[j]));
    assert!(std[j] > 0.0 && std[j] > last.ols_std_error[j], "{last:?}");
    let mut v = serde_json::to_value(model).expect("serialises");
    let o = v.as_object_mut().expect("an object");
    for k in ["dcf_std_rad", "dcf_distance_std_rad_per_m", "turn_gain_std"] {
        o.remove(k).expect("written");
    }
    let old = TedrisModel::from_json(&v.to_string()).expect("loads");
    assert_eq!(
        (
            old.dcf_std_rad,
            old.dcf_distance_std_rad_per_m,
            old.turn_gain_std
        ),
        (None, None, None)
    );
    let mut bad = model.clone();
    bad.turn_gain_std = Some(-1e-3);
    let text = serde_json::to_string(&bad).expect("serialises");
    let e = TedrisModel::from_json(&text).expect_err("refused");
    assert!(e.to_string().contains("turn_gain_std"), "{e}");
}

#[test]
fn a_refit_on_blocks_the_heading_contradicts_replaced_the_regressions() {
    let mut m = trained();
    let before = m.model.clone().expect("model");
    // Each block's γ paired with the ω of a block half the drive away:
    // regressions on these blocks no longer turn with the wheels
    // (unguarded, the refit took the ω slope from 0.64 to 0.15).
    let tuples = before.repositories.all_sorted();
    let half = tuples.len() / 2;
    let r = &before.repositories;
    let mut corrupted = Repositories::new(r.straight, r.min_fill, r.max_fill);
    for (i, tu) in tuples.iter().enumerate() {
        let mut x = *tu;
        x.gamma_rad = tuples[(i + half) % tuples.len()].gamma_rad;
        corrupted.insert(x);
    }
    if let Some(model) = m.model.as_mut() {
        model.repositories = corrupted;
    }
    let (accepted, refused) = (m.accepted_refits, m.refused_refits);
    let t = m.last_t.expect("samples");
    m.refit(t);
    assert_eq!(betas(m.model.as_ref().expect("model")), betas(&before));
    assert_eq!(
        (m.accepted_refits, m.refused_refits),
        (accepted, refused + 1)
    );
    assert_eq!(m.checks().refused_refits, refused + 1);
}

#[test]
fn a_refit_on_the_drives_own_blocks_is_accepted() {
    let mut m = trained();
    // The current regressions fitted on the first three quarters of the
    // blocks; the refit takes in the last quarter, which the heading
    // does not contradict.
    let before = m.model.clone().expect("model");
    let mut fewer = before.clone();
    let tuples = before.repositories.all_sorted();
    let r = &before.repositories;
    fewer.repositories = Repositories::new(r.straight, r.min_fill, r.max_fill);
    for tu in &tuples[..tuples.len() * 3 / 4] {
        fewer.repositories.insert(*tu);
    }
    let fitted = fewer.refit().expect("fit");
    m.model = Some(TedrisModel {
        dcf_rad: before.dcf_rad,
        dcf_distance_rad_per_m: before.dcf_distance_rad_per_m,
        turn_gain: before.turn_gain,
        distance_scale: before.distance_scale,
        per_metre_straight: before.per_metre_straight,
        course_convention: before.course_convention,
        repositories: before.repositories.clone(),
        ..fitted.clone()
    });
    let (accepted, refused) = (m.accepted_refits, m.refused_refits);
    let t = m.last_t.expect("samples");
    m.refit(t);
    assert_eq!(
        (m.accepted_refits, m.refused_refits),
        (accepted + 1, refused)
    );
    let after = m.model.as_ref().expect("model");
    assert_ne!(betas(after), betas(&fitted));
}
