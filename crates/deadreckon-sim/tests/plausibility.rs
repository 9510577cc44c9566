//! The cross-stream plausibility checks of `deadreckon_core::plausibility` on
//! simulated drives: silent on clean drives of many randomized cars, and each
//! mistake of units or clocks caught by the check meant for it.

use deadreckon_core::drive::Wheels;
use deadreckon_core::plausibility::{check, Finding, Severity};
use deadreckon_core::{drive::yaw_rad_to_course_deg, Drive};
use deadreckon_sim::{family::CarFamily, simulate, Scenario};

fn ticks_drive() -> Drive {
    simulate(&Scenario::builtin("evaluation").unwrap(), 4)
        .unwrap()
        .drive
}

fn speeds_drive() -> Drive {
    let car = CarFamily::draw(5);
    simulate(&car.drive(7, 300.0), 7).unwrap().drive
}

fn only(findings: &[Finding], check_name: &str) -> String {
    assert!(
        findings
            .iter()
            .any(|f| f.check == check_name && f.severity == Severity::Error),
        "no {check_name} error in {findings:#?}"
    );
    findings
        .iter()
        .filter(|f| f.check == check_name)
        .map(|f| f.message.clone())
        .collect::<Vec<_>>()
        .join("; ")
}

#[test]
fn clean_drives_pass_every_check() {
    assert_eq!(check(&ticks_drive()), vec![]);
    for car in 1..=8 {
        let fam = CarFamily::draw(car);
        let d = simulate(&fam.drive(100 + car, 300.0), car).unwrap().drive;
        assert_eq!(check(&d), vec![], "car {car}");
    }
}

#[test]
fn gnss_times_in_milliseconds_and_another_clock() {
    let mut d = ticks_drive();
    for g in &mut d.gnss {
        g.t_s *= 1000.0;
    }
    let m = only(&check(&d), "time_overlap");
    assert!(m.contains("gnss") && m.contains("milliseconds"), "{m}");
    let mut d = ticks_drive();
    for g in &mut d.yaw_rate {
        g.t_s += 1.0e5;
    }
    let m = only(&check(&d), "time_overlap");
    assert!(m.contains("yaw_rate"), "{m}");
}

#[test]
fn can_speed_in_kmh() {
    let mut d = ticks_drive();
    for s in &mut d.speed {
        s.value *= 3.6;
    }
    let m = only(&check(&d), "can_vs_wheel_speed");
    assert!(m.contains("km/h"), "{m}");
}

#[test]
fn wheel_speeds_in_kmh() {
    let mut d = speeds_drive();
    let Wheels::Speeds(rows) = &mut d.wheels else {
        panic!("the family writes wheel speeds")
    };
    for r in rows.iter_mut() {
        r.fl_mps *= 3.6;
        r.fr_mps *= 3.6;
        r.rl_mps *= 3.6;
        r.rr_mps *= 3.6;
    }
    let m = only(&check(&d), "gnss_vs_wheel_distance");
    assert!(m.contains("km/h"), "{m}");
}

#[test]
fn cumulative_tick_counters_and_a_wrong_ticks_per_rev() {
    let mut d = ticks_drive();
    let Wheels::Ticks(rows) = &mut d.wheels else {
        panic!()
    };
    let mut sum = [0i64; 4];
    for r in rows.iter_mut() {
        sum = [sum[0] + r.fl, sum[1] + r.fr, sum[2] + r.rl, sum[3] + r.rr];
        (r.fl, r.fr, r.rl, r.rr) = (sum[0], sum[1], sum[2], sum[3]);
    }
    only(&check(&d), "wheel_speed_range");
    let mut d = ticks_drive();
    d.vehicle.ticks_per_rev /= 2;
    let m = only(&check(&d), "gnss_vs_wheel_distance");
    assert!(m.contains("0.5"), "{m}");
    // Too many ticks per revolution (a count per edge of a quadrature
    // encoder): the wheels travel half the GNSS distance (1.979 while every
    // simulated tone ring started at an edge).
    let mut d = ticks_drive();
    d.vehicle.ticks_per_rev *= 2;
    let m = only(&check(&d), "gnss_vs_wheel_distance");
    assert!(m.contains("is 1.987 times"), "{m}");
}

#[test]
fn lengths_in_millimetres() {
    let mut d = ticks_drive();
    d.vehicle.wheelbase_m *= 1000.0;
    let m = only(&check(&d), "vehicle_lengths");
    assert!(m.contains("millimetres"), "{m}");
    let mut d = ticks_drive();
    d.vehicle.wheel_circumference_m *= 1000.0;
    only(&check(&d), "vehicle_lengths");
}

#[test]
fn a_flipped_gyro_sign_and_degrees_per_second() {
    let mut d = ticks_drive();
    for g in &mut d.yaw_rate {
        g.value = -g.value;
    }
    let m = only(&check(&d), "gyro_vs_wheel_yaw_rate");
    assert!(m.contains("other way"), "{m}");
    let mut d = ticks_drive();
    for g in &mut d.yaw_rate {
        g.value = g.value.to_degrees();
    }
    let m = only(&check(&d), "gyro_vs_wheel_yaw_rate");
    assert!(m.contains("degrees"), "{m}");
}

#[test]
fn course_in_radians_or_counter_clockwise_from_east() {
    let d = ticks_drive();
    assert!(d.gnss.iter().filter(|g| g.course_deg.is_some()).count() > 100);
    let mut rad = d.clone();
    for g in &mut rad.gnss {
        g.course_deg = g.course_deg.map(f64::to_radians);
    }
    let m = only(&check(&rad), "course_vs_track");
    assert!(m.contains("radians"), "{m}");
    let mut ccw = d.clone();
    for g in &mut ccw.gnss {
        // The yaw in degrees (counter-clockwise from east) written as the course.
        g.course_deg = g.course_deg.map(|c| 90.0 - c);
    }
    let m = only(&check(&ccw), "course_vs_track");
    assert!(m.contains("counter-clockwise"), "{m}");
    // The helper of the drive format converts the other way round.
    assert!((yaw_rad_to_course_deg(0.0) - 90.0).abs() < 1e-12);
}

#[test]
fn a_stuck_gnss_fix_for_200_s() {
    let mut d = ticks_drive();
    let t0 = d.gnss[0].t_s + 100.0;
    let i = d.gnss.partition_point(|g| g.t_s < t0);
    let (e, n) = (d.gnss[i].east_m, d.gnss[i].north_m);
    for g in d
        .gnss
        .iter_mut()
        .filter(|g| g.t_s >= t0 && g.t_s < t0 + 200.0)
    {
        (g.east_m, g.north_m) = (e, n);
    }
    let m = only(&check(&d), "stuck_gnss");
    assert!(m.contains("repeating"), "{m}");
}

#[test]
fn latitude_and_longitude_swapped() {
    use deadreckon_core::geo::{en_to_geodetic, geodetic_to_en};
    use deadreckon_core::vehicle::Origin;
    // gnss.csv written in latitude/longitude with the two columns swapped,
    // read as the reader does without [origin]: about the first fix.
    // Longitudes within ±90° (others cannot be read as latitudes: the
    // reader refuses them on their line), with and without the course.
    for ((lat0, lon0), course) in [(48.1, 11.6), (52.5, 13.4), (-33.9, 18.4), (35.7, 51.4)]
        .into_iter()
        .flat_map(|o| [(o, true), (o, false)])
    {
        let mut d = ticks_drive();
        if !course {
            for g in &mut d.gnss {
                g.course_deg = None;
            }
        }
        let origin = Origin::new(lat0, lon0);
        let swapped: Vec<(f64, f64)> = d
            .gnss
            .iter()
            .map(|g| {
                let (lat, lon) = en_to_geodetic(&origin, g.east_m, g.north_m);
                (lon, lat)
            })
            .collect();
        let (a, b) = swapped[0];
        let first = Origin::new(a, b);
        let mut bad = d.clone();
        for (g, &(lat, lon)) in bad.gnss.iter_mut().zip(&swapped) {
            (g.east_m, g.north_m) = geodetic_to_en(&first, lat, lon);
        }
        // The track is mirrored: it turns the other way from the wheels
        // (33–39 of 36–41 turns measured), whether or not the distances
        // (1.0–1.3× the wheels') or a course give it away too.
        let m = only(&check(&bad), "gnss_turns_vs_wheel_turns");
        assert!(
            m.contains("latitude and longitude swapped"),
            "({lat0}, {lon0}): {m}"
        );
    }
}
