//! The calibrated vehicle-model keys of params.toml read back: the
//! steering's ratio, offset and understeer gradient (`[steering]`) and the
//! rear-axle side-slip gradient (`[side_slip]`), as `calibrate --out`
//! writes them ([`crate::calibrate::CarCalibration::params_extra`]). Only
//! the values marked `estimated = true` are taken. Applying them to a
//! vehicle ([`StoredModel::apply`]) is the caller's choice: these tables
//! report what the drive measured. What the commands apply is the `[model]`
//! table, the additions `--corrections auto` chose on held-back GNSS
//! ([`deadreckon_core::model_options`]; the vehicle.toml keys of the same
//! names set them by hand).

use deadreckon_core::kinematics::steering::UNDERSTEER_NAME;
use deadreckon_core::side_slip::NAME as SLIP_NAME;
use deadreckon_core::Vehicle;

/// The estimated model keys found in a params.toml (each `None` when absent
/// or not estimated).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StoredModel {
    /// `[steering] steering_ratio`.
    pub steering_ratio: Option<f64>,
    /// `[steering] steering_offset_rad`, rad.
    pub steering_offset_rad: Option<f64>,
    /// `[steering] understeer_gradient_rad_per_mps2`, rad per m/s².
    pub understeer_gradient_rad_per_mps2: Option<f64>,
    /// `[side_slip] rear_slip_gradient_rad_per_mps2`, rad per m/s².
    pub rear_slip_gradient_rad_per_mps2: Option<f64>,
}

/// The value of `table.key` when it is marked estimated: `Ok(None)` when
/// absent or not estimated, an error naming the key when malformed.
fn estimated(table: &toml::Table, section: &str, key: &str) -> Result<Option<f64>, String> {
    let Some(e) = table.get(key) else {
        return Ok(None);
    };
    let e = e
        .as_table()
        .ok_or_else(|| format!("`{section}.{key}` must be a table"))?;
    if !e
        .get("estimated")
        .and_then(|v| v.as_bool())
        .unwrap_or(false)
    {
        return Ok(None);
    }
    let v = e
        .get("value")
        .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
        .ok_or_else(|| format!("`{section}.{key}.value` must be a number"))?;
    if !v.is_finite() {
        return Err(format!("`{section}.{key}.value` = {v} is not finite"));
    }
    Ok(Some(v))
}

/// Reads the estimated model keys from the extra keys of a params.toml
/// (`deadreckon_io::read_params_with_extra`).
pub fn stored_model(extra: &toml::Table) -> Result<StoredModel, String> {
    let mut m = StoredModel::default();
    if let Some(st) = extra.get("steering") {
        let st = st.as_table().ok_or("`steering` must be a table")?;
        m.steering_ratio = estimated(st, "steering", "steering_ratio")?;
        m.steering_offset_rad = estimated(st, "steering", "steering_offset_rad")?;
        m.understeer_gradient_rad_per_mps2 = estimated(st, "steering", UNDERSTEER_NAME)?;
    }
    if let Some(s) = extra.get("side_slip") {
        let s = s.as_table().ok_or("`side_slip` must be a table")?;
        m.rear_slip_gradient_rad_per_mps2 = estimated(s, "side_slip", SLIP_NAME)?;
    }
    Ok(m)
}

impl StoredModel {
    /// True when no key was estimated.
    pub fn is_empty(&self) -> bool {
        *self == StoredModel::default()
    }

    /// Sets the vehicle's keys to the stored estimates (the others keep
    /// theirs); an error when the result is not a valid vehicle.
    pub fn apply(&self, vehicle: &mut Vehicle) -> Result<(), deadreckon_core::Error> {
        let mut v = vehicle.clone();
        if let Some(r) = self.steering_ratio {
            v.steering_ratio = r;
        }
        if let Some(o) = self.steering_offset_rad {
            v.steering_offset_rad = o;
        }
        if let Some(k) = self.understeer_gradient_rad_per_mps2 {
            v.understeer_gradient_rad_per_mps2 = k;
        }
        if let Some(g) = self.rear_slip_gradient_rad_per_mps2 {
            v.rear_slip_gradient_rad_per_mps2 = g;
        }
        v.validate()?;
        *vehicle = v;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deadreckon_core::kinematics::steering::SteeringCalibration;
    use deadreckon_core::kinematics::ParamEstimate;
    use deadreckon_core::side_slip::SideSlip;
    use deadreckon_core::{Params, ParamsWithStd};

    fn est(name: &str, value: f64, estimated: bool) -> ParamEstimate {
        ParamEstimate {
            name: name.into(),
            value,
            std: estimated.then_some(value * 0.01),
            estimated,
            reason: (!estimated).then(|| "not determined".into()),
        }
    }

    #[test]
    fn the_calibrated_model_keys_survive_params_toml() {
        let steering = SteeringCalibration {
            ratio: est("steering_ratio", 15.81, true),
            offset: est("steering_offset_rad", 0.021, true),
            understeer: Some(est(UNDERSTEER_NAME, 0.0031, true)),
            samples: 1000,
            rms_rad: 0.01,
        };
        let slip = SideSlip {
            gradient: est(SLIP_NAME, 0.0049, true),
            fitted: 0.0049,
            fitted_std: 0.0002,
            scale_residual: 0.0,
            yaw_offset_rad: 0.0,
            blocks: 90,
            rms_lateral_accel_mps2: 0.9,
        };
        let mut extra = toml::Table::new();
        extra.insert(
            "steering".into(),
            crate::calibrate::steering_toml(&steering).into(),
        );
        extra.insert(
            "side_slip".into(),
            crate::calibrate::side_slip_toml(&slip).into(),
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("params.toml");
        let v = Vehicle::paper_car();
        let p = Params::nominal(&v);
        deadreckon_io::write_params(&path, &ParamsWithStd { params: p, std: p }, Some(&extra))
            .unwrap();
        let (_, back) = deadreckon_io::read_params_with_extra(&path).unwrap();
        let m = stored_model(&back).unwrap();
        assert_eq!(
            m,
            StoredModel {
                steering_ratio: Some(15.81),
                steering_offset_rad: Some(0.021),
                understeer_gradient_rad_per_mps2: Some(0.0031),
                rear_slip_gradient_rad_per_mps2: Some(0.0049),
            }
        );
        let mut vehicle = v.clone();
        m.apply(&mut vehicle).unwrap();
        assert_eq!(vehicle.rear_slip_gradient_rad_per_mps2, 0.0049);
        assert_eq!(vehicle.steering_ratio, 15.81);
        // Not estimated: not taken; absent tables: nothing.
        let slip_not = SideSlip {
            gradient: est(SLIP_NAME, 0.0, false),
            ..slip
        };
        extra.insert(
            "side_slip".into(),
            crate::calibrate::side_slip_toml(&slip_not).into(),
        );
        assert_eq!(
            stored_model(&extra)
                .unwrap()
                .rear_slip_gradient_rad_per_mps2,
            None
        );
        assert!(stored_model(&toml::Table::new()).unwrap().is_empty());
        // A value that makes no vehicle is refused, the vehicle unchanged.
        let bad = StoredModel {
            rear_slip_gradient_rad_per_mps2: Some(0.5),
            ..StoredModel::default()
        };
        let mut unchanged = v.clone();
        assert!(bad.apply(&mut unchanged).is_err());
        assert_eq!(unchanged, v);
    }
}
