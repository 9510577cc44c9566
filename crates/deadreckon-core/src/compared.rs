//! What an outage's errors compare: a point of the vehicle against a
//! reference, as one result type for every estimator.
//!
//! Positions are typed by the point of the vehicle they are of, in the
//! spirit of sguaba's frames: a [`Position<RearAxle>`] (the filter's state,
//! TedriS's track, the truth) and a [`Position<Antenna>`] (a GNSS fix) cannot
//! be subtracted from each other; one is moved to the other's point through
//! the lever arm first ([`Position::<RearAxle>::antenna`],
//! [`Position::<Antenna>::rear_axle`]). An [`OutageResult`] records which
//! point was compared ([`ComparedPoint`]) and against what ([`Against`]),
//! and derives every figure the commands print from its error series: mean,
//! largest and final error, and the time and distance before the error
//! first reaches a threshold.

use std::marker::PhantomData;

/// A point of the vehicle positions are of.
pub trait Point: Copy {
    /// Which one, as a value.
    const POINT: ComparedPoint;
}

/// The middle of the rear axle: the state's point, the truth's, TedriS's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RearAxle;

/// The GNSS antenna, `gnss_lever_arm_m` ahead of the rear axle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Antenna;

impl Point for RearAxle {
    const POINT: ComparedPoint = ComparedPoint::RearAxle;
}

impl Point for Antenna {
    const POINT: ComparedPoint = ComparedPoint::Antenna;
}

/// The point an outage's errors were measured at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ComparedPoint {
    /// The rear axle.
    RearAxle,
    /// The GNSS antenna.
    Antenna,
}

impl ComparedPoint {
    /// "rear axle" or "antenna".
    pub fn name(self) -> &'static str {
        match self {
            ComparedPoint::RearAxle => "rear axle",
            ComparedPoint::Antenna => "antenna",
        }
    }
}

/// An east/north position of the point `P`, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Position<P: Point> {
    /// East, m.
    pub east_m: f64,
    /// North, m.
    pub north_m: f64,
    point: PhantomData<P>,
}

impl<P: Point> Position<P> {
    /// The position `(east_m, north_m)` of `P`.
    pub fn new(east_m: f64, north_m: f64) -> Self {
        Position {
            east_m,
            north_m,
            point: PhantomData,
        }
    }

    /// The horizontal distance to another position of the same point, m.
    pub fn distance_to(&self, other: &Position<P>) -> f64 {
        (self.east_m - other.east_m).hypot(self.north_m - other.north_m)
    }

    /// This position less another of the same point, `[east, north]`, m.
    pub fn offset_from(&self, other: &Position<P>) -> [f64; 2] {
        [self.east_m - other.east_m, self.north_m - other.north_m]
    }
}

impl Position<RearAxle> {
    /// The antenna of a vehicle whose rear axle is here, heading `yaw_rad`,
    /// with the antenna `lever_m` ahead.
    pub fn antenna(self, yaw_rad: f64, lever_m: f64) -> Position<Antenna> {
        Position::new(
            self.east_m + lever_m * yaw_rad.cos(),
            self.north_m + lever_m * yaw_rad.sin(),
        )
    }
}

impl Position<Antenna> {
    /// The rear axle of a vehicle whose antenna is here, heading `yaw_rad`,
    /// with the antenna `lever_m` ahead.
    pub fn rear_axle(self, yaw_rad: f64, lever_m: f64) -> Position<RearAxle> {
        Position::new(
            self.east_m - lever_m * yaw_rad.cos(),
            self.north_m - lever_m * yaw_rad.sin(),
        )
    }
}

/// What an outage's errors are measured against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Against {
    /// `truth.csv`.
    Truth,
    /// `truth.csv` shifted onto the estimate at the outage start (drives
    /// whose estimate has no absolute position, as the paper's robot).
    TruthAlignedAtStart,
    /// The GNSS fixes hidden in the outage.
    Gnss,
}

impl Against {
    /// "truth", "truth aligned at outage start" or "gnss".
    pub fn name(self) -> &'static str {
        match self {
            Against::Truth => "truth",
            Against::TruthAlignedAtStart => "truth aligned at outage start",
            Against::Gnss => "gnss",
        }
    }
}

impl std::fmt::Display for Against {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl serde::Serialize for Against {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// One outage's errors, for any estimator: the window, what was compared
/// with what, and the error series every figure is derived from.
#[derive(Debug, Clone, PartialEq)]
pub struct OutageResult {
    /// Start, s.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
    /// The reference.
    pub against: Against,
    /// The point compared.
    pub point: ComparedPoint,
    /// The errors: (time since the outage start, s; horizontal error, m).
    pub errors: Vec<(f64, f64)>,
    /// The distance travelled from the outage start at each error, m
    /// (empty when the estimator does not say).
    pub travelled_m: Vec<f64>,
    /// The distance travelled over the window, m (NaN when unknown).
    pub distance_m: f64,
    /// The filter's yaw standard deviation where the dead reckoning started,
    /// rad (`None` when the estimator has none).
    pub start_yaw_std_rad: Option<f64>,
    /// The estimator's covariance of the compared point at each error, m²
    /// (empty when the estimator has none): the part of the error bound
    /// the factor inflates ([`crate::bound`]).
    pub covariances_m2: Vec<crate::bound::Cov2>,
    /// The receiver's offset, m², the same at every error of the window
    /// (the declared accuracy of the last fix before the outage,
    /// [`crate::bound`]'s floor, not inflated; zero where the estimator
    /// carries it in its state, and without `covariances_m2`). Once per
    /// window, not per error: 48 B an error less with `reference_m2`
    /// (docs/performance.md, "Sixth round").
    pub floor_m2: crate::bound::Cov2,
    /// The reference's own covariance, m², the same at every error (a
    /// hidden fix's noise; zero for the truth, and without
    /// `covariances_m2`).
    pub reference_m2: crate::bound::Cov2,
    /// The log-likelihood of the last hidden fix under the dead
    /// reckoning's own prediction of it: the antenna plus the wander the
    /// filter still expects, with their covariance and the fix's declared
    /// noise (`None` where not computed:
    /// [`crate::outage::through_windows_against_fixes`] computes it).
    pub fix_log_likelihood: Option<f64>,
}

impl OutageResult {
    /// The errors of point `P` over `[start_s, end_s)`; `travelled_m` is
    /// empty or holds one distance per error.
    pub fn new<P: Point>(
        start_s: f64,
        end_s: f64,
        against: Against,
        errors: Vec<(f64, f64)>,
        travelled_m: Vec<f64>,
        distance_m: f64,
    ) -> Self {
        debug_assert!(travelled_m.is_empty() || travelled_m.len() == errors.len());
        OutageResult {
            start_s,
            end_s,
            against,
            point: P::POINT,
            errors,
            travelled_m,
            distance_m,
            start_yaw_std_rad: None,
            covariances_m2: Vec::new(),
            floor_m2: crate::bound::Cov2::circular(0.0),
            reference_m2: crate::bound::Cov2::circular(0.0),
            fix_log_likelihood: None,
        }
    }

    /// Mean error, m (NaN without errors).
    pub fn mean_m(&self) -> f64 {
        if self.errors.is_empty() {
            return f64::NAN;
        }
        self.errors.iter().map(|e| e.1).sum::<f64>() / self.errors.len() as f64
    }

    /// Largest error, m (NaN without errors).
    pub fn max_m(&self) -> f64 {
        self.errors.iter().map(|e| e.1).fold(f64::NAN, f64::max)
    }

    /// The first error, m: the one the GNSS-aided run handed over at the
    /// outage start (its first point, one epoch in; NaN without errors). It
    /// is in every later error too, so the final error less this one is what
    /// the dead reckoning itself added, at most.
    pub fn start_m(&self) -> f64 {
        self.errors.first().map_or(f64::NAN, |e| e.1)
    }

    /// The last error, m (NaN without errors).
    pub fn final_m(&self) -> f64 {
        self.errors.last().map_or(f64::NAN, |e| e.1)
    }

    /// The first error at or above `threshold_m`.
    fn first_reaching(&self, threshold_m: f64) -> Option<usize> {
        self.errors.iter().position(|e| e.1 >= threshold_m)
    }

    /// Time from the outage start until the error first reaches
    /// `threshold_m`, s (`None`: it never does).
    pub fn time_to(&self, threshold_m: f64) -> Option<f64> {
        self.first_reaching(threshold_m).map(|i| self.errors[i].0)
    }

    /// Distance travelled from the outage start until the error first
    /// reaches `threshold_m`, m (`None`: it never does, or the distance is
    /// not known).
    pub fn distance_to(&self, threshold_m: f64) -> Option<f64> {
        self.first_reaching(threshold_m)
            .and_then(|i| self.travelled_m.get(i).copied())
    }

    /// Points compared.
    pub fn points(&self) -> usize {
        self.errors.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_antenna_position_is_compared_with_an_antenna_position() {
        let axle = Position::<RearAxle>::new(10.0, 5.0);
        let fix = Position::<Antenna>::new(11.0, 5.0);
        // Heading east, antenna 1 m ahead: the fix is exactly at the antenna.
        assert!(axle.antenna(0.0, 1.0).distance_to(&fix) < 1e-12);
        assert!(fix.rear_axle(0.0, 1.0).distance_to(&axle) < 1e-12);
        // Heading north, the antenna is 1 m north of the axle: √2 from the fix.
        let d = axle
            .antenna(std::f64::consts::FRAC_PI_2, 1.0)
            .distance_to(&fix);
        assert!((d - 2f64.sqrt()).abs() < 1e-12, "{d}");
    }

    #[test]
    fn the_estimators_outage_figures_differed_in_metric_reference_and_point() {
        let r = OutageResult::new::<Antenna>(
            10.0,
            20.0,
            Against::Gnss,
            vec![(1.0, 0.5), (2.0, 1.0), (3.0, 2.0), (4.0, 1.5)],
            vec![10.0, 20.0, 30.0, 40.0],
            45.0,
        );
        assert_eq!(r.point, ComparedPoint::Antenna);
        assert_eq!(r.against.name(), "gnss");
        assert_eq!(r.mean_m(), 1.25);
        assert_eq!(r.max_m(), 2.0);
        assert_eq!(r.final_m(), 1.5);
        assert_eq!(r.start_m(), 0.5);
        // Both the time and the distance to a threshold, from the same error.
        assert_eq!(r.time_to(1.0), Some(2.0));
        assert_eq!(r.distance_to(1.0), Some(20.0));
        assert_eq!(r.time_to(3.0), None);
        assert_eq!(r.distance_to(3.0), None);
        let empty =
            OutageResult::new::<RearAxle>(0.0, 1.0, Against::Truth, vec![], vec![], f64::NAN);
        assert!(empty.mean_m().is_nan() && empty.max_m().is_nan() && empty.final_m().is_nan());
        assert!(empty.start_m().is_nan());
        assert_eq!(empty.point, ComparedPoint::RearAxle);
    }
}
