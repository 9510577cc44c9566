//! The drives and trained models of `family_outages.rs`'s family cars
//! that several of its tests use, made once per process on the first test
//! that asks ([`OnceLock`]): the family tests, car 8's regression tests,
//! `short_training_drives`' test drives and `calibration_std`'s training
//! drives and models.

use std::sync::OnceLock;

use deadreckon_core::Drive;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::{simulate, SimOutput};
use deadreckon_tedris::{train, TedrisConfig, TedrisModel};

/// The slot of car `seed` among those whose drives several tests share:
/// the development cars 1–12 and the held-out cars 201–212 (the family
/// tests, car 8's regression tests, `short_training_drives`' test drives,
/// and `calibration_std`'s training drives and models).
pub(crate) fn shared_slot(seed: u64) -> Option<usize> {
    match seed {
        1..=12 => Some((seed - 1) as usize),
        201..=212 => Some((seed - 201 + 12) as usize),
        _ => None,
    }
}

/// Car `seed`'s 500 s test drive (seed `2000 + seed`): the family's test
/// drive and `short_training_drives`' for every training length.
fn simulate_test_drive(seed: u64) -> SimOutput {
    let car = CarFamily::draw(seed);
    simulate(&car.drive(2000 + seed, 500.0), 2000 + seed).expect("test")
}

/// A family car's 900 s training drive (seed `1000 + seed`) and the model
/// TedriS's default configuration trains on it.
pub(crate) struct Trained {
    pub(crate) drive: Drive,
    pub(crate) model: TedrisModel,
}

fn train_car(seed: u64) -> Trained {
    let car = CarFamily::draw(seed);
    let drive = simulate(&car.drive(1000 + seed, 900.0), 1000 + seed)
        .expect("train drive")
        .drive;
    let (model, _) = train(&drive, TedrisConfig::default(), None).expect("trained");
    Trained { drive, model }
}

/// Computed once per process for the shared cars, on the first test that
/// asks; other cars' are computed each time.
static TEST_DRIVES: [OnceLock<SimOutput>; 24] = [const { OnceLock::new() }; 24];
static TRAINED: [OnceLock<Trained>; 24] = [const { OnceLock::new() }; 24];

/// Shared car `seed`'s test drive (`seed` has a [`shared_slot`]).
pub(crate) fn shared_test_drive(seed: u64) -> &'static SimOutput {
    let slot = shared_slot(seed).expect("a shared car");
    TEST_DRIVES[slot].get_or_init(|| simulate_test_drive(seed))
}

/// Shared car `seed`'s training drive and model (`seed` has a
/// [`shared_slot`]).
pub(crate) fn shared_trained(seed: u64) -> &'static Trained {
    let slot = shared_slot(seed).expect("a shared car");
    TRAINED[slot].get_or_init(|| train_car(seed))
}

/// Runs `f` on car `seed`'s test drive, from the shared ones when it is one.
pub(crate) fn with_test_drive<R>(seed: u64, f: impl FnOnce(&SimOutput) -> R) -> R {
    if shared_slot(seed).is_some() {
        f(shared_test_drive(seed))
    } else {
        f(&simulate_test_drive(seed))
    }
}

/// Runs `f` on car `seed`'s training drive and model, from the shared ones
/// when it is one.
pub(crate) fn with_trained<R>(seed: u64, f: impl FnOnce(&Trained) -> R) -> R {
    if shared_slot(seed).is_some() {
        f(shared_trained(seed))
    } else {
        f(&train_car(seed))
    }
}

/// The first of the twelve development cars the family tests run: 1, or
/// `TEDRIS_FAMILY_FIRST_CAR` (101 runs cars 101–112).
pub(crate) fn first_car() -> u64 {
    std::env::var("TEDRIS_FAMILY_FIRST_CAR")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1)
}
