//! `vehicle.toml`, `params.toml` and `truth_params.toml`.

use std::fs;
use std::path::Path;

use deadreckon_core::{Params, ParamsWithStd, Vehicle};

use crate::{atomic_write, IoError};

fn read_text(path: &Path) -> Result<String, IoError> {
    match fs::read_to_string(path) {
        Ok(s) => Ok(s),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(IoError::MissingFile {
            path: path.to_path_buf(),
            note: "file not found".into(),
        }),
        Err(e) => Err(IoError::io(path, e)),
    }
}

fn toml_error(path: &Path, message: impl std::fmt::Display) -> IoError {
    IoError::Toml {
        path: path.to_path_buf(),
        message: message.to_string().trim_end().to_string(),
    }
}

fn invalid(path: &Path, source: deadreckon_core::Error) -> IoError {
    IoError::Invalid {
        path: path.to_path_buf(),
        source,
    }
}

/// Reads `vehicle.toml` and checks it with [`Vehicle::validate`]. Unknown keys
/// are errors (a misspelt noise key must not silently fall back to its default).
pub fn read_vehicle(path: &Path) -> Result<Vehicle, IoError> {
    parse_vehicle(&read_text(path)?, path)
}

/// [`read_vehicle`] on the text of a `vehicle.toml` (embedders hand it over
/// as text); `path` only names it in errors.
pub fn parse_vehicle(text: &str, path: &Path) -> Result<Vehicle, IoError> {
    let vehicle: Vehicle = toml::from_str(text).map_err(|e| toml_error(path, e))?;
    vehicle.validate().map_err(|e| invalid(path, e))?;
    Ok(vehicle)
}

/// Writes `vehicle.toml` atomically (every key, noise included, so the file
/// documents the values used).
pub fn write_vehicle(path: &Path, vehicle: &Vehicle) -> Result<(), IoError> {
    vehicle.validate().map_err(|e| invalid(path, e))?;
    let text = toml::to_string(vehicle).map_err(|e| toml_error(path, e))?;
    atomic_write(path, |w| w.write_all(text.as_bytes()))
}

/// Reads `truth_params.toml`: exactly the six keys of [`Params`], checked with
/// [`Params::validate`].
pub fn read_truth_params(path: &Path) -> Result<Params, IoError> {
    let text = read_text(path)?;
    let params: Params = toml::from_str(&text).map_err(|e| toml_error(path, e))?;
    params.validate().map_err(|e| invalid(path, e))?;
    Ok(params)
}

/// Writes `truth_params.toml` atomically.
pub fn write_truth_params(path: &Path, params: &Params) -> Result<(), IoError> {
    params.validate().map_err(|e| invalid(path, e))?;
    let text = toml::to_string(params).map_err(|e| toml_error(path, e))?;
    atomic_write(path, |w| w.write_all(text.as_bytes()))
}

/// Reads `params.toml`: the six keys of [`Params`] at top level and, optionally,
/// a `[std]` table with the same six keys. A missing `[std]` table gives all-zero
/// standard errors (unknown uncertainty is not invented). Other keys and tables
/// (written through `extra` by [`write_params`]) are ignored: see
/// [`read_params_with_extra`] to get them.
pub fn read_params(path: &Path) -> Result<ParamsWithStd, IoError> {
    read_params_with_extra(path).map(|(p, _)| p)
}

/// Like [`read_params`], also returning every other top-level key and table.
pub fn read_params_with_extra(path: &Path) -> Result<(ParamsWithStd, toml::Table), IoError> {
    parse_params_with_extra(&read_text(path)?, path)
}

/// [`read_params_with_extra`] on the text of a `params.toml`; `path` only
/// names it in errors.
pub fn parse_params_with_extra(
    text: &str,
    path: &Path,
) -> Result<(ParamsWithStd, toml::Table), IoError> {
    let mut table: toml::Table = text.parse().map_err(|e| toml_error(path, e))?;
    if let Some(shape) = table.get("shape").and_then(|v| v.as_str()) {
        return Err(IoError::OtherShape {
            path: path.to_path_buf(),
            shape: shape.to_string(),
        });
    }
    let params = take_params(path, &mut table, None)?;
    params.validate().map_err(|e| invalid(path, e))?;
    let std = match table.remove("std") {
        None => Params::from_array([0.0; 6]),
        Some(toml::Value::Table(mut t)) => {
            let std = take_params(path, &mut t, Some("std"))?;
            if let Some(k) = t.keys().next() {
                return Err(toml_error(path, format!("unknown key `std.{k}`")));
            }
            std
        }
        Some(_) => return Err(toml_error(path, "`std` must be a table")),
    };
    check_std(path, &std)?;
    Ok((ParamsWithStd { params, std }, table))
}

/// Standard errors must be finite and non-negative.
fn check_std(path: &Path, std: &Params) -> Result<(), IoError> {
    for (name, v) in Params::NAMES.iter().zip(std.to_array()) {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(
                path,
                deadreckon_core::Error::param(
                    format!("std.{name}"),
                    v,
                    deadreckon_core::Rule::NonNegative { zero_means: None },
                ),
            ));
        }
    }
    Ok(())
}

/// Removes the six parameter keys from `table`, as numbers (integers accepted).
fn take_params(
    path: &Path,
    table: &mut toml::Table,
    prefix: Option<&str>,
) -> Result<Params, IoError> {
    let mut a = [0.0; 6];
    for (slot, name) in a.iter_mut().zip(Params::NAMES) {
        let key = match prefix {
            Some(p) => format!("{p}.{name}"),
            None => name.to_string(),
        };
        *slot = match table.remove(name) {
            Some(toml::Value::Float(v)) => v,
            Some(toml::Value::Integer(v)) => v as f64,
            Some(other) => {
                return Err(toml_error(
                    path,
                    format!("`{key}` must be a number, found a {}", other.type_str()),
                ))
            }
            None => return Err(toml_error(path, format!("missing key `{key}`"))),
        };
    }
    Ok(Params::from_array(a))
}

/// Writes `params.toml` atomically: the six keys, then the keys and tables of
/// `extra` (e.g. how the calibration was run), then `[std]`. The estimates must
/// pass [`Params::validate`], the standard errors be finite and non-negative,
/// and `extra` must not reuse a parameter key or `std`.
pub fn write_params(
    path: &Path,
    params: &ParamsWithStd,
    extra: Option<&toml::Table>,
) -> Result<(), IoError> {
    params.params.validate().map_err(|e| invalid(path, e))?;
    check_std(path, &params.std)?;
    let mut text = toml::to_string(&params.params).map_err(|e| toml_error(path, e))?;
    if let Some(extra) = extra {
        if let Some(k) = extra
            .keys()
            .find(|k| *k == "std" || Params::NAMES.contains(&k.as_str()))
        {
            return Err(toml_error(
                path,
                format!("extra key `{k}` clashes with a params.toml key"),
            ));
        }
        if !extra.is_empty() {
            text.push('\n');
            text.push_str(&toml::to_string(extra).map_err(|e| toml_error(path, e))?);
        }
    }
    #[derive(serde::Serialize)]
    struct Std<'a> {
        std: &'a Params,
    }
    text.push('\n');
    text.push_str(&toml::to_string(&Std { std: &params.std }).map_err(|e| toml_error(path, e))?);
    // The concatenation must be one valid document that reads back the same.
    match read_params_str(&text) {
        Some(back) if back == *params => {}
        _ => {
            return Err(IoError::Unwritable {
                path: path.to_path_buf(),
                message: "the extra table does not combine with the parameters into valid TOML"
                    .into(),
            })
        }
    }
    atomic_write(path, |w| w.write_all(text.as_bytes()))
}

fn read_params_str(text: &str) -> Option<ParamsWithStd> {
    let mut table: toml::Table = text.parse().ok()?;
    let p = Path::new("params.toml");
    let params = take_params(p, &mut table, None).ok()?;
    let mut std = match table.remove("std")? {
        toml::Value::Table(t) => t,
        _ => return None,
    };
    let std = take_params(p, &mut std, Some("std")).ok()?;
    Some(ParamsWithStd { params, std })
}
