//! The calibrated vehicle-model keys of params.toml read back: the
//! steering's ratio, offset and understeer gradient (`[steering]`) and the
//! rear-axle side-slip gradient (`[side_slip]`), as `calibrate --out`
//! writes them ([`crate::calibrate::CarCalibration::params_tables`]). Only
//! the values marked `estimated = true` are taken. Applying them to a
//! vehicle ([`StoredModel::apply`]) is the caller's choice: these tables
//! report what the drive measured. What the commands apply is the `[model]`
//! table, the additions `--corrections auto` chose on held-back GNSS
//! ([`deadreckon_core::model_options`]; the vehicle.toml keys of the same
//! names set them by hand).

use deadreckon_core::kinematics::steering::UNDERSTEER_NAME;
use deadreckon_core::side_slip::NAME as SLIP_NAME;
use deadreckon_core::Vehicle;

use crate::params_tables::{EstimateTable, ParamsTables};

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

/// The estimated value of an optional estimate table (`Ok(None)` when
/// absent or not estimated).
fn estimated(e: Option<&EstimateTable>, key: &str) -> Result<Option<f64>, String> {
    e.map_or(Ok(None), |e| e.estimated_value(key))
}

/// Reads the estimated model keys from a params.toml's tables
/// ([`crate::params_file::ParamsFile::tables`]).
pub fn stored_model(tables: &ParamsTables) -> Result<StoredModel, String> {
    let mut m = StoredModel::default();
    if let Some(st) = &tables.steering {
        m.steering_ratio = estimated(st.steering_ratio.as_ref(), "steering.steering_ratio")?;
        m.steering_offset_rad = estimated(
            st.steering_offset_rad.as_ref(),
            "steering.steering_offset_rad",
        )?;
        m.understeer_gradient_rad_per_mps2 = estimated(
            st.understeer_gradient_rad_per_mps2.as_ref(),
            &format!("steering.{UNDERSTEER_NAME}"),
        )?;
    }
    if let Some(s) = &tables.side_slip {
        m.rear_slip_gradient_rad_per_mps2 = estimated(
            s.rear_slip_gradient_rad_per_mps2.as_ref(),
            &format!("side_slip.{SLIP_NAME}"),
        )?;
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

    use crate::params_file::ParamsFile;
    use crate::params_tables::{SideSlipTable, SteeringTable};

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
        let mut tables = ParamsTables {
            steering: Some(SteeringTable::of(&steering)),
            side_slip: Some(SideSlipTable::of(&slip)),
            ..Default::default()
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("params.toml");
        let v = Vehicle::paper_car();
        let p = Params::nominal(&v);
        let file =
            ParamsFile::new(ParamsWithStd { params: p, std: p }, tables.clone(), "p").unwrap();
        file.write(&path).unwrap();
        let back = ParamsFile::read(path.to_str().unwrap()).unwrap();
        assert_eq!(back, file);
        let m = stored_model(&back.tables).unwrap();
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
        tables.side_slip = Some(SideSlipTable::of(&slip_not));
        assert_eq!(
            stored_model(&tables)
                .unwrap()
                .rear_slip_gradient_rad_per_mps2,
            None
        );
        assert!(stored_model(&ParamsTables::default()).unwrap().is_empty());
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
