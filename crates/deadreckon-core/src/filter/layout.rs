//! Which states a [`super::Filter`] carries: the car's five ([`CarLayout`])
//! or those and the six parameters ([`AugmentedLayout`]), and where each
//! parameter, the receiver's wander and the walking gyro bias sit
//! ([`Layout`]).

/// Index of the gyro bias in the augmented state.
pub const AUG_BIAS: usize = 5;
/// Index of the speed scale in the augmented state.
pub const AUG_SCALE: usize = 6;
/// Index of the first inverse circumference (FL, then FR, RL, RR) in the augmented state.
pub const AUG_INV_CIRC: usize = 7;
/// Dimension of the augmented state.
pub const N_AUG: usize = 11;

/// Where the six parameters live in a state of dimension `N`.
pub trait Layout<const N: usize>: Copy + std::fmt::Debug + Default + PartialEq {
    /// A short name (`car`, `augmented`).
    const NAME: &'static str;
    /// Index in the state of parameter `j` (0 gyro bias, 1 speed scale, 2..6 the
    /// inverse circumferences FL..RR), or `None` when the parameters are fixed.
    fn param_index(j: usize) -> Option<usize>;
    /// Index in the state of the receiver's wander east (north follows), or
    /// `None` when the fixes are taken as white ([`crate::gnss_error`]).
    fn wander_index() -> Option<usize> {
        None
    }
    /// Whether the gyro bias (parameter 0, which must then be a state) walks
    /// by `noise.gyro_bias_walk_rps_per_sqrt_s` ([`crate::gyro_drift`]);
    /// the calibration's parameters are constants.
    fn bias_walks() -> bool {
        false
    }
}

/// The five car states; the parameters are fixed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CarLayout;

impl Layout<{ crate::model::N }> for CarLayout {
    const NAME: &'static str = "car";
    fn param_index(_j: usize) -> Option<usize> {
        None
    }
}

/// The car states then the six parameters, estimated as constant states.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AugmentedLayout;

impl Layout<N_AUG> for AugmentedLayout {
    const NAME: &'static str = "augmented";
    fn param_index(j: usize) -> Option<usize> {
        (j < 6).then_some(5 + j)
    }
}
