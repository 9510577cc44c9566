//! Through the C API the filter gives `deadreckon stream`'s poses bit for
//! bit: typed pushes and lines, wheel and per-reading timing, with and
//! without learning, across a save and restore in the middle of a drive, and
//! from a state file `stream --state` wrote.

mod common;

use common::*;
use deadreckon_api::stream::{self, StreamOptions};
use deadreckon_core::ekf::{Event, FilterOptions, Timing};
use deadreckon_core::online::{LearnTargets, Online};
use deadreckon_core::Drive;
use deadreckon_ffi::*;

fn stream_options(o: &DrOptions) -> StreamOptions {
    StreamOptions {
        filter: FilterOptions {
            timing: if o.timing == DR_TIMING_EACH {
                Timing::EachMeasurement
            } else {
                Timing::WheelEpochs
            },
            ..Default::default()
        },
        state: None,
        learn: o.learn,
        params_out: None,
        save_every_s: None,
        skip_bad_lines: false,
        last_part: false,
    }
}

/// The filter `stream` opens (nominal parameters, default prior).
fn rust_online(d: &Drive, o: &DrOptions) -> Result<Online, deadreckon_api::Error> {
    let s = stream::start_params("nominal", &d.vehicle).unwrap();
    stream::open(
        &d.vehicle,
        &s.params,
        &s.prior,
        &s.stored,
        &stream_options(o),
    )
}

fn rust_poses(online: &mut Online, events: &[Event], finish: bool) -> Vec<DrPose> {
    let mut out = Vec::new();
    for ev in events {
        online.push(*ev, &mut |p| out.push(p.into())).unwrap();
    }
    if finish {
        online.finish(&mut |p| out.push(p.into())).unwrap();
    }
    out
}

fn ffi_poses(f: *mut DrFilter, events: &[Event], lines: bool, finish: bool) -> Vec<DrPose> {
    let mut out = Vec::new();
    for ev in events {
        let s = if lines {
            push_line(f, &deadreckon_io::events::to_line(ev))
        } else {
            push_event(f, ev)
        };
        assert_eq!(s, DrStatus::Ok, "t={}: {}", ev.t_s, last_error());
        drain(f, &mut out);
    }
    if finish {
        // SAFETY: a live handle.
        assert_eq!(unsafe { dr_finish(f) }, DrStatus::Ok, "{}", last_error());
        drain(f, &mut out);
    }
    out
}

fn options(timing: i32, learn: bool) -> DrOptions {
    DrOptions { timing, learn }
}

#[test]
fn typed_pushes_and_lines_give_the_poses_of_stream_bit_for_bit() {
    let d = drive(90.0);
    let evs = events(&d);
    let v = vehicle_toml(&d);
    for timing in [DR_TIMING_WHEEL, DR_TIMING_EACH] {
        for learn in [false, true] {
            let o = options(timing, learn);
            let Ok(mut online) = rust_online(&d, &o) else {
                // Learning per reading may be refused with this noise: then
                // the C API refuses it too.
                let mut f = std::ptr::null_mut();
                // SAFETY: valid text, options and out.
                let s = unsafe {
                    dr_filter_new(v.as_ptr().cast(), v.len(), std::ptr::null(), 0, &o, &mut f)
                };
                assert_eq!(s, DrStatus::BadConfig);
                assert!(f.is_null());
                continue;
            };
            let want = rust_poses(&mut online, &evs, true);
            assert!(want.len() > 1000, "{} poses", want.len());
            for lines in [false, true] {
                let f = new_filter(&v, o);
                let got = ffi_poses(f, &evs, lines, true);
                assert_eq!(
                    got.len(),
                    want.len(),
                    "timing {timing} learn {learn} lines {lines}"
                );
                assert!(
                    got == want,
                    "timing {timing} learn {learn} lines {lines}: poses differ"
                );
                let mut latest = std::mem::MaybeUninit::uninit();
                // SAFETY: a live handle, a writable pose.
                assert_eq!(
                    unsafe { dr_latest_pose(f, latest.as_mut_ptr()) },
                    DrStatus::Ok
                );
                // SAFETY: written on success.
                assert_eq!(unsafe { latest.assume_init() }, *want.last().unwrap());
                let mut g = std::mem::MaybeUninit::uninit();
                // SAFETY: as above.
                assert_eq!(unsafe { dr_gate_counts(f, g.as_mut_ptr()) }, DrStatus::Ok);
                let gates: DrGateCounts = online.stats().unwrap().gates.into();
                // SAFETY: written on success.
                assert_eq!(unsafe { g.assume_init() }, gates);
                assert!(gates.accepted[DrGateSensor::Gnss as usize] > 10);
                let mut l = std::mem::MaybeUninit::uninit();
                // SAFETY: as above.
                let s = unsafe { dr_learned(f, l.as_mut_ptr()) };
                match online.learned(&LearnTargets::default()) {
                    Some(want) => {
                        assert_eq!(s, DrStatus::Ok);
                        // SAFETY: written on success.
                        assert_eq!(unsafe { l.assume_init() }, DrLearned::from(want));
                    }
                    None => assert_eq!(s, DrStatus::NotAvailable),
                }
                free(f);
            }
        }
    }
}

#[test]
fn a_save_and_restore_mid_drive_continues_bit_for_bit() {
    let d = drive(90.0);
    let evs = events(&d);
    let v = vehicle_toml(&d);
    for learn in [false, true] {
        let o = options(DR_TIMING_WHEEL, learn);
        let want = rust_poses(&mut rust_online(&d, &o).unwrap(), &evs, true);
        let half = evs.len() / 2;
        let f = new_filter(&v, o);
        let mut got = ffi_poses(f, &evs[..half], false, false);
        let bytes = save(f);
        // The bytes are what `stream --state` writes for the same events.
        let mut online = rust_online(&d, &o).unwrap();
        rust_poses(&mut online, &evs[..half], false);
        assert_eq!(bytes, stream::state_text(&online).unwrap().into_bytes());
        free(f);
        let g = restore(&bytes);
        got.extend(ffi_poses(g, &evs[half..], false, true));
        free(g);
        assert_eq!(got.len(), want.len());
        assert!(got == want, "learn {learn}: poses differ after the restore");
    }
}

#[test]
fn a_state_file_written_by_stream_resumes_through_the_c_api() {
    let d = drive(60.0);
    let evs = events(&d);
    let o = options(DR_TIMING_WHEEL, true);
    let want = rust_poses(&mut rust_online(&d, &o).unwrap(), &evs, true);
    let dir = tempfile::tempdir().unwrap();
    let state = dir.path().join("state.json");
    let half = evs.len() / 2;
    // The first half through `stream`'s own loop, which writes the state file.
    let text: String = evs[..half]
        .iter()
        .map(|e| deadreckon_io::events::to_line(e) + "\n")
        .collect();
    let so = StreamOptions {
        state: Some(state.clone()),
        ..stream_options(&o)
    };
    let mut online = rust_online(&d, &o).unwrap();
    let mut printed = Vec::new();
    stream::run(
        &mut online,
        text.as_bytes(),
        "events",
        &mut printed,
        &so,
        &mut |_| {},
    )
    .unwrap();
    // `stream` ran the epochs still waiting at the end of its input; the
    // state it wrote continues as if never cut (docs/events.md).
    let mut got: Vec<DrPose> = String::from_utf8(printed)
        .unwrap()
        .lines()
        .map(|l| {
            serde_json::from_str::<deadreckon_core::TrackPoint>(l)
                .unwrap()
                .into()
        })
        .collect();
    let f = restore(&std::fs::read(&state).unwrap());
    got.extend(ffi_poses(f, &evs[half..], false, true));
    free(f);
    assert_eq!(got.len(), want.len());
    assert!(
        got == want,
        "poses differ after resuming stream's state file"
    );
}

/// Issue 31: the 95 % bound of each pose through the C API
/// (`dr_next_pose_with_bound`, `dr_latest_bound`) is `stream`'s, from the
/// `[bound]` factor of the params.toml text, bit for bit.
#[test]
fn the_c_api_gives_each_pose_the_bound_of_stream() {
    let d = drive(90.0);
    let evs = events(&d);
    let v = vehicle_toml(&d);
    let o = options(DR_TIMING_WHEEL, false);
    // Nominal parameters with a fitted factor of 1.7.
    let mut extra = toml::Table::new();
    let fit = deadreckon_core::bound::BoundFit {
        method: deadreckon_core::bound::Method::Conformal,
        k: 1.7,
        windows: 20,
        outage_s: 30.0,
        step_s: 10.0,
    };
    extra.insert(
        "bound".into(),
        deadreckon_api::bound::bound_toml(&fit).into(),
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("params.toml");
    let nominal = deadreckon_core::ParamsWithStd {
        params: deadreckon_core::Params::nominal(&d.vehicle),
        std: stream::default_prior(),
    };
    deadreckon_io::write_params(&path, &nominal, Some(&extra)).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let s = stream::start_params_from_text(&text, "p.toml").unwrap();
    assert_eq!(s.bound, fit);
    let mut online = stream::open(
        &d.vehicle,
        &s.params,
        &s.prior,
        &s.stored,
        &stream_options(&o),
    )
    .unwrap()
    .with_bound(s.bound);
    let mut want = Vec::new();
    for ev in &evs {
        online.push_poses(*ev, &mut |p| want.push(p)).unwrap();
    }
    online.end_poses(&mut |p| want.push(p)).unwrap();
    let mut f = std::ptr::null_mut();
    // SAFETY: valid texts, options and out.
    let s = unsafe {
        dr_filter_new(
            v.as_ptr().cast(),
            v.len(),
            text.as_ptr().cast(),
            text.len(),
            &o,
            &mut f,
        )
    };
    assert_eq!(s, DrStatus::Ok, "{}", last_error());
    let mut got: Vec<(DrPose, f64)> = Vec::new();
    let take = |f: *mut DrFilter, got: &mut Vec<(DrPose, f64)>| loop {
        let mut pose = std::mem::MaybeUninit::<DrPose>::zeroed();
        let mut b = f64::NAN;
        // SAFETY: a live handle, writable outputs.
        match unsafe { dr_next_pose_with_bound(f, pose.as_mut_ptr(), &mut b) } {
            DrStatus::Ok => got.push((unsafe { pose.assume_init() }, b)),
            DrStatus::NoPose => break,
            s => panic!("{s:?}: {}", last_error()),
        }
    };
    for ev in &evs {
        assert_eq!(push_event(f, ev), DrStatus::Ok, "{}", last_error());
        take(f, &mut got);
    }
    // SAFETY: a live handle.
    assert_eq!(unsafe { dr_finish(f) }, DrStatus::Ok, "{}", last_error());
    take(f, &mut got);
    assert_eq!(got.len(), want.len());
    assert!(want.len() > 1000, "{} poses", want.len());
    for (g, w) in got.iter().zip(&want) {
        assert!(g.0 == DrPose::from(w.point), "pose at {}", w.point.t_s);
        assert_eq!(
            g.1.to_bits(),
            w.bound_95_m.to_bits(),
            "bound at {}",
            w.point.t_s
        );
    }
    // The factor is in it: r(1.7² P + σ² I), the filter's covariance
    // inflated and the last fix's declared accuracy not (docs/bound.md),
    // wider than the filter's own bound and narrower than 1.7 times it.
    let plain = deadreckon_core::bound::BoundFit::FILTER;
    let last = want.last().unwrap();
    let fix_std = d.gnss.last().unwrap().std_m;
    let unit = deadreckon_core::bound_pose::point_bound_m(&plain, &last.point, fix_std);
    let p = &last.point.cov_pose;
    let inflated = deadreckon_core::bound::Cov2 {
        ee_m2: 1.7 * 1.7 * p[0] + fix_std * fix_std,
        en_m2: 1.7 * 1.7 * 0.5 * (p[1] + p[3]),
        nn_m2: 1.7 * 1.7 * p[4] + fix_std * fix_std,
    };
    let want_last = deadreckon_core::bound::radius(&inflated);
    assert!(
        (last.bound_95_m / want_last - 1.0).abs() < 1e-12
            && last.bound_95_m > unit
            && last.bound_95_m < 1.7 * unit,
        "{} {want_last} {unit}",
        last.bound_95_m
    );
    let mut latest = f64::NAN;
    // SAFETY: a live handle, a writable bound.
    assert_eq!(unsafe { dr_latest_bound(f, &mut latest) }, DrStatus::Ok);
    assert_eq!(latest.to_bits(), last.bound_95_m.to_bits());
    // SAFETY: the handle, freed once.
    unsafe { dr_filter_free(f) };
}
