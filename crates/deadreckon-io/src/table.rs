//! A checked CSV table: columns found by header name, every field parsed with
//! its file, line and column in the error, timestamps checked to increase.

use std::borrow::Cow;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use crate::IoError;

/// The plausible range of a column's unit; a value outside it is reported with a hint.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Limit {
    /// Yaw rate, rad/s: |v| ≤ 5.
    YawRate,
    /// Steering wheel angle, rad: |v| ≤ 4π.
    SteeringWheel,
    /// Yaw, rad: |v| ≤ 2π + 0.01.
    Yaw,
    /// Course, degrees clockwise from north: -180 ≤ v ≤ 360.
    Course,
    /// Standard deviation, m: 0 < v ≤ 1000.
    Std,
    /// Speed, m/s: |v| ≤ 100.
    Speed,
    /// Latitude, degrees: |v| ≤ 90.
    Lat,
    /// Longitude, degrees: |v| ≤ 180.
    Lon,
    /// Specific force, m/s²: |v| ≤ 200.
    Accel,
    /// Ellipsoidal height, m: -1000 ≤ v ≤ 10000.
    Height,
}

/// Lowest accepted ellipsoidal height, m (the Dead Sea shore is about -400 m
/// above the geoid, the geoid within ±110 m of the ellipsoid).
pub(crate) const MIN_HEIGHT_M: f64 = -1000.0;
/// Highest accepted ellipsoidal height, m (above every road).
pub(crate) const MAX_HEIGHT_M: f64 = 10_000.0;

/// Largest accepted |specific force|, m/s² (about 20 g).
pub(crate) const MAX_ACCEL_MPS2: f64 = 200.0;

/// Largest accepted |yaw rate|, rad/s.
pub(crate) const MAX_YAW_RATE_RPS: f64 = 5.0;
/// Largest accepted |steering wheel angle|, rad (two turns).
pub(crate) const MAX_STEERING_WHEEL_RAD: f64 = 4.0 * PI;
/// Largest accepted |yaw|, rad.
pub(crate) const MAX_YAW_RAD: f64 = 2.0 * PI + 0.01;
/// Largest accepted |speed|, m/s.
pub(crate) const MAX_SPEED_MPS: f64 = 100.0;
/// Largest accepted standard deviation, m.
pub(crate) const MAX_STD_M: f64 = 1000.0;

impl Limit {
    /// `None` when `v` is plausible, otherwise the hint.
    fn check(self, v: f64) -> Option<String> {
        let ok = match self {
            Limit::YawRate => v.abs() <= MAX_YAW_RATE_RPS,
            Limit::SteeringWheel => v.abs() <= MAX_STEERING_WHEEL_RAD,
            Limit::Yaw => v.abs() <= MAX_YAW_RAD,
            Limit::Course => (-180.0..=360.0).contains(&v),
            Limit::Std => v > 0.0 && v <= MAX_STD_M,
            Limit::Speed => v.abs() <= MAX_SPEED_MPS,
            Limit::Lat => v.abs() <= 90.0,
            Limit::Lon => v.abs() <= 180.0,
            Limit::Accel => v.abs() <= MAX_ACCEL_MPS2,
            Limit::Height => (MIN_HEIGHT_M..=MAX_HEIGHT_M).contains(&v),
        };
        if ok {
            return None;
        }
        Some(
            match self {
                Limit::YawRate => "|yaw rate| > 5 rad/s looks like degrees/s; expected rad/s",
                Limit::SteeringWheel => {
                    "|steering wheel angle| > 4π rad looks like degrees; expected radians"
                }
                Limit::Yaw => "|yaw| > 2π + 0.01 rad looks like degrees; expected radians",
                Limit::Course => {
                    "expected degrees clockwise from north in [-180, 360]"
                }
                Limit::Std => {
                    "expected a standard deviation in metres, > 0 and ≤ 1000 (a variance, or millimetres?)"
                }
                Limit::Speed => "|speed| > 100 m/s looks like km/h or mph; expected m/s",
                Limit::Lat => "not a latitude in degrees (expected -90 to 90)",
                Limit::Lon => "not a longitude in degrees (expected -180 to 180)",
                Limit::Height => {
                    "not a height above the WGS84 ellipsoid in metres (expected -1000 to 10000; millimetres or feet?)"
                }
                Limit::Accel => {
                    "|specific force| > 200 m/s² looks like mm/s² or cm/s²; expected m/s²"
                }
            }
            .to_string(),
        )
    }
}

/// A CSV file being read: its header and the reader positioned on the first row.
pub(crate) struct Table<'a> {
    file: PathBuf,
    columns: HashMap<String, usize>,
    width: usize,
    bytes: &'a [u8],
    reader: csv::Reader<&'a [u8]>,
}

impl<'a> Table<'a> {
    /// Parses the header of `bytes` (the content of `file`).
    pub(crate) fn new(file: &Path, bytes: &'a [u8]) -> Result<Self, IoError> {
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(true)
            .flexible(true)
            .from_reader(bytes);
        let header = reader
            .byte_headers()
            .map_err(|e| csv_error(file, &e))?
            .clone();
        let mut columns = HashMap::new();
        for (i, name) in header.iter().enumerate() {
            let name = String::from_utf8_lossy(name.trim_ascii()).into_owned();
            if name.is_empty() {
                continue;
            }
            if columns.insert(name.clone(), i).is_some() {
                return Err(IoError::DuplicateColumn {
                    file: file.to_path_buf(),
                    column: name,
                });
            }
        }
        Ok(Table {
            file: file.to_path_buf(),
            columns,
            width: header.len(),
            bytes,
            reader,
        })
    }

    /// The index of a required column.
    pub(crate) fn col(&self, name: &'static str) -> Result<Col, IoError> {
        self.opt_col(name).ok_or_else(|| IoError::MissingColumn {
            file: self.file.clone(),
            column: name.to_string(),
        })
    }

    /// The index of an optional column, if present.
    pub(crate) fn opt_col(&self, name: &'static str) -> Option<Col> {
        self.columns.get(name).map(|&index| Col { index, name })
    }

    /// True when the header has the column.
    pub(crate) fn has(&self, name: &str) -> bool {
        self.columns.contains_key(name)
    }

    /// Reads every row with `f`, checking the field count and that `t_s`
    /// (which must be a column) is finite and strictly increasing.
    pub(crate) fn rows<T>(
        mut self,
        mut f: impl FnMut(&Row<'_>) -> Result<T, IoError>,
    ) -> Result<Vec<T>, IoError> {
        let t_col = self.col("t_s")?;
        // One row a line: sized once (no doubling), so a drive in memory is
        // what its rows need.
        let lines = self.bytes.iter().filter(|&&b| b == b'\n').count();
        let mut out = Vec::with_capacity(lines + 1);
        let mut record = csv::ByteRecord::new();
        let mut prev_t: Option<f64> = None;
        loop {
            match self.reader.read_byte_record(&mut record) {
                Ok(true) => {}
                Ok(false) => break,
                Err(e) => return Err(csv_error(&self.file, &e)),
            }
            let line = record
                .position()
                .map_or(0, |p| first_line(self.bytes, p.byte(), p.line()));
            if record.len() != self.width {
                return Err(IoError::WrongFieldCount {
                    file: self.file.clone(),
                    line,
                    expected: self.width,
                    found: record.len(),
                });
            }
            let row = Row {
                file: &self.file,
                line,
                record: &record,
            };
            let t = row.f64(t_col)?;
            if let Some(prev) = prev_t {
                if t <= prev {
                    return Err(IoError::TimeNotIncreasing {
                        file: self.file.clone(),
                        line,
                        t_s: t,
                        prev_t_s: prev,
                    });
                }
            }
            prev_t = Some(t);
            out.push(f(&row)?);
        }
        Ok(out)
    }
}

/// A column of the contract, found in the header.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Col {
    index: usize,
    name: &'static str,
}

/// One data row.
pub(crate) struct Row<'r> {
    file: &'r Path,
    line: u64,
    record: &'r csv::ByteRecord,
}

impl Row<'_> {
    /// The field's bytes without surrounding ASCII whitespace (trimmed here,
    /// not by the CSV reader, whose trimming copies every record).
    fn bytes(&self, col: Col) -> &[u8] {
        self.record.get(col.index).unwrap_or_default().trim_ascii()
    }

    /// The field as text, for numbers and messages.
    fn text(&self, col: Col) -> Cow<'_, str> {
        let bytes = self.bytes(col);
        match std::str::from_utf8(bytes) {
            Ok(s) => Cow::Borrowed(s),
            Err(_) => String::from_utf8_lossy(bytes),
        }
    }

    fn bad(&self, col: Col, expected: &'static str) -> IoError {
        IoError::BadNumber {
            file: self.file.to_path_buf(),
            line: self.line,
            column: col.name.to_string(),
            text: self.text(col).into_owned(),
            expected,
        }
    }

    /// A required finite number.
    pub(crate) fn f64(&self, col: Col) -> Result<f64, IoError> {
        let text = self.text(col);
        let v: f64 = text.parse().map_err(|_| self.bad(col, "a number"))?;
        if !v.is_finite() {
            return Err(IoError::NonFinite {
                file: self.file.to_path_buf(),
                line: self.line,
                column: col.name.to_string(),
                text: text.into_owned(),
            });
        }
        Ok(v)
    }

    /// A required finite number within `limit`.
    pub(crate) fn checked(&self, col: Col, limit: Limit) -> Result<f64, IoError> {
        let v = self.f64(col)?;
        match limit.check(v) {
            None => Ok(v),
            Some(hint) => Err(IoError::OutOfRange {
                file: self.file.to_path_buf(),
                line: self.line,
                column: col.name.to_string(),
                value: v,
                hint,
            }),
        }
    }

    /// An optional column: absent column or empty field give `None`.
    pub(crate) fn opt_checked(
        &self,
        col: Option<Col>,
        limit: Limit,
    ) -> Result<Option<f64>, IoError> {
        match col {
            Some(c) if !self.bytes(c).is_empty() => self.checked(c, limit).map(Some),
            _ => Ok(None),
        }
    }

    /// A required integer.
    pub(crate) fn i64(&self, col: Col) -> Result<i64, IoError> {
        self.text(col)
            .parse()
            .map_err(|_| self.bad(col, "an integer"))
    }
}

/// The line a record really starts on: the CSV reader gives the position just
/// after the previous record, before any blank lines it then skipped.
fn first_line(bytes: &[u8], byte: u64, line: u64) -> u64 {
    let start = usize::try_from(byte).unwrap_or(usize::MAX);
    let rest = bytes.get(start..).unwrap_or_default();
    let mut line = line;
    let mut i = 0;
    while let Some(&b) = rest.get(i) {
        match b {
            b'\n' => line += 1,
            b'\r' if rest.get(i + 1) != Some(&b'\n') => line += 1,
            b'\r' => {}
            _ => break,
        }
        i += 1;
    }
    line
}

fn csv_error(file: &Path, e: &csv::Error) -> IoError {
    let line = e.position().map_or(1, |p| p.line());
    IoError::Csv {
        file: file.to_path_buf(),
        line,
        message: e.to_string(),
    }
}
