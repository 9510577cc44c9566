//! Parameters bound to their vehicle (issue 29, item 5). `calibrate --out`
//! records in params.toml's `[vehicle]` table the vehicle the parameters
//! were calibrated for: the drive's `vehicle_id` where its vehicle.toml has
//! one, and the nominal geometry and circumference. Applying the file to a
//! drive of another vehicle, or values implausible for the drive's vehicle
//! (a circumference more than [`MAX_CIRCUMFERENCE_DEVIATION`] from its
//! nominal one, millimetres for metres), is refused with an error naming
//! both vehicles and the values, unless the user says so
//! (`--params-for-other-vehicle`). A file written before the record existed
//! is still taken, with a note that it names no vehicle. `calibrate` itself
//! rejects a fit outside the same bound ([`implausible_circumference`] in
//! [`crate::calibration::calibrate`]): it does not write what the other
//! commands refuse.

use deadreckon_core::{Params, Vehicle};

use crate::Error;

/// A calibrated circumference further than this fraction from the
/// vehicle's nominal `wheel_circumference_m` is implausible for that
/// vehicle: a tyre's rolling circumference moves 1–3 % from its nominal
/// size with pressure, wear, load and speed (the simulator's families draw
/// up to 1.4 %, the golden drive calibrates 1.8 % above nominal), while
/// another tyre size or another vehicle's file is further (the comma2k19
/// RAV4's 2.29 m on the paper car's 1.92 m nominal is 19 %).
pub const MAX_CIRCUMFERENCE_DEVIATION: f64 = 0.05;

/// Two nominal lengths (geometry, circumference) of one vehicle agree to
/// this fraction (they are copied from one vehicle.toml; the margin only
/// absorbs decimal printing).
const SAME_NOMINAL: f64 = 1e-6;

/// The vehicle a params.toml was calibrated for (its `[vehicle]` table,
/// written and read through this type).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleRecord {
    /// The drive's `vehicle_id` (none when its vehicle.toml has none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vehicle_id: Option<String>,
    /// Nominal wheelbase, m.
    pub wheelbase_m: f64,
    /// Nominal front track, m.
    pub track_front_m: f64,
    /// Nominal rear track, m.
    pub track_rear_m: f64,
    /// Nominal wheel circumference, m.
    pub wheel_circumference_m: f64,
}

impl VehicleRecord {
    /// The record of `vehicle`.
    pub fn of(vehicle: &Vehicle) -> Self {
        VehicleRecord {
            vehicle_id: vehicle.vehicle_id.clone(),
            wheelbase_m: vehicle.wheelbase_m,
            track_front_m: vehicle.track_front_m,
            track_rear_m: vehicle.track_rear_m,
            wheel_circumference_m: vehicle.wheel_circumference_m,
        }
    }

    /// The record checked as read from `spec`: every length finite and
    /// positive (an error names the key).
    pub fn check(&self, spec: &str) -> Result<(), Error> {
        for (k, v) in [
            ("wheelbase_m", self.wheelbase_m),
            ("track_front_m", self.track_front_m),
            ("track_rear_m", self.track_rear_m),
            ("wheel_circumference_m", self.wheel_circumference_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Invalid(format!(
                    "{spec}: `vehicle.{k}` = {v} is not a length (finite, positive)"
                )));
            }
        }
        Ok(())
    }

    /// In words: `vehicle_id "x", wheelbase 2.58 m, tracks 1.48/1.46 m,
    /// nominal circumference 1.92 m`.
    pub fn describe(&self) -> String {
        let id = match &self.vehicle_id {
            Some(id) => format!("vehicle_id {id:?}, "),
            None => "no vehicle_id, ".into(),
        };
        format!(
            "{id}wheelbase {} m, tracks {}/{} m, nominal circumference {} m",
            self.wheelbase_m, self.track_front_m, self.track_rear_m, self.wheel_circumference_m
        )
    }

    /// Whether the record names `vehicle`: the same `vehicle_id` when both
    /// have one, else the same nominal geometry and circumference.
    pub fn is(&self, vehicle: &Vehicle) -> bool {
        if let (Some(a), Some(b)) = (&self.vehicle_id, &vehicle.vehicle_id) {
            return a == b;
        }
        let other = VehicleRecord::of(vehicle);
        [
            (self.wheelbase_m, other.wheelbase_m),
            (self.track_front_m, other.track_front_m),
            (self.track_rear_m, other.track_rear_m),
            (self.wheel_circumference_m, other.wheel_circumference_m),
        ]
        .iter()
        .all(|&(a, b)| (a - b).abs() <= SAME_NOMINAL * a.abs().max(b.abs()))
    }
}

/// What a params.toml's binding check found that is not an error: the
/// note the commands print (a file naming no vehicle, or one applied with
/// `--params-for-other-vehicle`).
pub type Note = Option<String>;

/// Refuses `params` (read from `spec`, whose `[vehicle]` record is
/// `record`) for a drive of `vehicle`: another vehicle's file, or a
/// circumference implausible for `vehicle` (further than
/// [`MAX_CIRCUMFERENCE_DEVIATION`] from its nominal, with a hint at
/// millimetres or centimetres). With `allow_other` nothing is refused and
/// the note says what was let through.
pub fn check(
    spec: &str,
    record: Option<&VehicleRecord>,
    params: &Params,
    vehicle: &Vehicle,
    allow_other: bool,
) -> Result<Note, Error> {
    let mut problems = Vec::new();
    if let Some(r) = record.filter(|r| !r.is(vehicle)) {
        problems.push(format!(
            "{spec} was calibrated for another vehicle ({}) than the drive's ({})",
            r.describe(),
            VehicleRecord::of(vehicle).describe()
        ));
    }
    if let Err(e) = check_circumferences(spec, params, vehicle) {
        problems.push(e);
    }
    let no_record = record
        .is_none()
        .then(|| format!("{spec} names no vehicle (written before params.toml recorded one): not checked against the drive's vehicle, only its circumferences"));
    if problems.is_empty() {
        return Ok(no_record);
    }
    if allow_other {
        return Ok(Some(format!(
            "applied with --params-for-other-vehicle: {}",
            problems.join("; ")
        )));
    }
    Err(Error::Invalid(format!(
        "{} (--params-for-other-vehicle to apply it anyway)",
        problems.join("; ")
    )))
}

/// The circumferences of `params` against `vehicle`'s nominal one: each
/// within [`MAX_CIRCUMFERENCE_DEVIATION`], or the message naming the file,
/// the key, both values and the likely mistake.
pub fn check_circumferences(spec: &str, p: &Params, vehicle: &Vehicle) -> Result<(), String> {
    let Some(bad) = implausible_circumference(p, vehicle) else {
        return Ok(());
    };
    let factor = bad.factor();
    let hint = if (factor / 1000.0 - 1.0).abs() < 0.5 {
        " (millimetres?)"
    } else if (factor / 100.0 - 1.0).abs() < 0.5 {
        " (centimetres?)"
    } else {
        " (another vehicle's parameters?)"
    };
    Err(format!("{spec}: {}", bad.describe(None, hint)))
}

/// A circumference further than [`MAX_CIRCUMFERENCE_DEVIATION`] from its
/// vehicle's nominal one; [`ImplausibleCircumference::describe`] is the one
/// wording of that refusal (a params.toml given to a drive, and a
/// calibration that settled there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImplausibleCircumference {
    /// The parameter's name (`circumference_fl_m`, …).
    pub name: &'static str,
    /// Its value, m.
    pub value_m: f64,
    /// The vehicle's nominal circumference, m.
    pub nominal_m: f64,
}

impl ImplausibleCircumference {
    /// The value over the nominal.
    pub fn factor(&self) -> f64 {
        self.value_m / self.nominal_m
    }

    /// "`name` = value m is ±x % from the vehicle's nominal
    /// wheel_circumference_m = n m`hint`, more than the 5 % a tyre varies",
    /// the value with `decimals` decimals (`None`: as it is).
    pub fn describe(&self, decimals: Option<usize>, hint: &str) -> String {
        let value = match decimals {
            Some(d) => format!("{:.*}", d, self.value_m),
            None => format!("{}", self.value_m),
        };
        format!(
            "{} = {value} m is {:+.1} % from the vehicle's nominal wheel_circumference_m = {} \
             m{hint}, more than the {} % a tyre varies",
            self.name,
            100.0 * (self.factor() - 1.0),
            self.nominal_m,
            100.0 * MAX_CIRCUMFERENCE_DEVIATION
        )
    }
}

/// The first circumference of `p` further than
/// [`MAX_CIRCUMFERENCE_DEVIATION`] from `vehicle`'s nominal.
pub fn implausible_circumference(
    p: &Params,
    vehicle: &Vehicle,
) -> Option<ImplausibleCircumference> {
    let nominal_m = vehicle.wheel_circumference_m;
    Params::NAMES[2..]
        .iter()
        .zip(p.circumferences())
        .map(|(name, value_m)| ImplausibleCircumference {
            name,
            value_m,
            nominal_m,
        })
        .find(|c| (c.factor() - 1.0).abs() > MAX_CIRCUMFERENCE_DEVIATION)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_names_its_vehicle_by_id_else_by_geometry() {
        let car = Vehicle::paper_car();
        let r = VehicleRecord::of(&car);
        assert!(r.is(&car));
        let mut other = car.clone();
        other.wheel_circumference_m = 2.29;
        assert!(!r.is(&other));
        // Ids decide when both have one.
        let mut a = car.clone();
        a.vehicle_id = Some("A".into());
        let mut b = other.clone();
        b.vehicle_id = Some("A".into());
        assert!(VehicleRecord::of(&a).is(&b));
        b.vehicle_id = Some("B".into());
        assert!(!VehicleRecord::of(&a).is(&b));
        // Round trip through params.toml's table.
        let table = toml::Table::try_from(VehicleRecord::of(&a)).unwrap();
        let back: VehicleRecord = table.try_into().unwrap();
        assert_eq!(back, VehicleRecord::of(&a));
        let mut bad = VehicleRecord::of(&a);
        bad.wheelbase_m = f64::NAN;
        let e = bad.check("p.toml").unwrap_err().to_string();
        assert!(e.contains("vehicle.wheelbase_m"), "{e}");
    }

    #[test]
    fn circumferences_beyond_five_per_cent_are_refused_and_allowed_when_asked() {
        let car = Vehicle::paper_car();
        let mut p = Params::nominal(&car);
        p.circumference_rl_m = 1.92 * 1.04;
        let r = VehicleRecord::of(&car);
        assert_eq!(check("p.toml", Some(&r), &p, &car, false).unwrap(), None);
        p.circumference_rl_m = 1.92 * 1.06;
        let e = check("p.toml", Some(&r), &p, &car, false).unwrap_err();
        assert!(e.to_string().contains("circumference_rl_m"), "{e}");
        assert!(e.to_string().contains("+6.0 %"), "{e}");
        let note = check("p.toml", Some(&r), &p, &car, true).unwrap().unwrap();
        assert!(note.starts_with("applied with --params-for-other-vehicle"));
        // An old file without the record: taken, with a note.
        p.circumference_rl_m = 1.92;
        let note = check("p.toml", None, &p, &car, false).unwrap().unwrap();
        assert!(note.contains("names no vehicle"), "{note}");
    }
}
