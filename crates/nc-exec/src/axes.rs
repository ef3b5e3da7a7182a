//! Positions by axis letter and over the machine's axes, as every part of
//! a run writes them.

/// Axes by letter (index = letter − `A`); positions in mm (degrees for
/// rotary axes).
pub type Position = [f64; 26];

/// The index of an axis letter in a [`Position`].
pub(crate) fn slot(axis: u8) -> usize {
    usize::from(axis - b'A')
}

/// A length on the µm grid positions lie on.
pub(crate) fn round3(value: f64) -> f64 {
    (value * 1000.0).round() / 1000.0
}

/// Positions over the machine's axes 1–6, in their order: what a step
/// keeps, so that a run of a million blocks stays small.
pub type Axes = [f64; MAX_AXES];

/// The most axes a machine has (axes 1–6).
pub const MAX_AXES: usize = 6;
