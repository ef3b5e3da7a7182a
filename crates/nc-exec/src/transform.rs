//! Coordinate transformations of G-group 11 (03 §3).
//!
//! - The recalculations of chapter 13 ([`Recalculation`]): mirroring G35
//!   and scale G36 act on the programmed values when a block is prepared,
//!   about the program zero; the independent offset G37 adds to the zero
//!   offset. G34 cancels all three. Compensation is not recalculated.
//! - The transformations of chapter 14 ([`Transformation`]): two planar
//!   ones (G38, G39) and a spatial one (G31) turn the program's fictive
//!   coordinates into the machine's real ones after interpolation, so the
//!   program, its offsets and compensation run unchanged and only the
//!   machine coordinates (and the rapid rates per real axis) see them.
//!
//! Where the manual leaves a choice open (03 §7), the reading taken is
//! stated where it is made.

use nalgebra::{Matrix3, Rotation3, Vector3};

use crate::axes::{Axes, MAX_AXES, Position, slot};

/// Mirroring, scale and independent offset in force (G35, G36, G37).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Recalculation {
    /// Letters whose direction is reversed, as a bit per letter (bit 0 = A).
    mirrored: u32,
    /// The scale of the linear axes.
    scale: f64,
    /// The independent offset by letter, which adds to the zero offset.
    pub shift: Position,
}

impl Default for Recalculation {
    fn default() -> Self {
        Recalculation { mirrored: 0, scale: 1.0, shift: [0.0; 26] }
    }
}

impl Recalculation {
    /// `G35` with its axes: a new set of mirrored axes replaces the old
    /// one, as the manual's example shows (000:5857–5861); none cancels.
    pub fn mirror(&mut self, letters: impl IntoIterator<Item = u8>) {
        self.mirrored = letters.into_iter().fold(0, |mask, letter| mask | 1 << slot(letter));
    }

    /// `G36`: one value is the scale, two are numerator and denominator,
    /// in the order written; none cancels. `None` for a scale of 0 or a
    /// zero denominator.
    pub fn set_scale(&mut self, values: &[f64]) -> Option<()> {
        let scale = match *values {
            [] => 1.0,
            [scale] => scale,
            [numerator, denominator, ..] => numerator / denominator,
        };
        (scale.is_finite() && scale != 0.0).then(|| self.scale = scale)
    }

    /// `G37`: the new vector replaces the whole old one (03 §7 q17 leaves
    /// it open; a partial update would make the result depend on history
    /// the block does not show).
    pub fn set_shift(&mut self, values: impl IntoIterator<Item = (u8, f64)>) {
        self.shift = [0.0; 26];
        for (letter, value) in values {
            self.shift[slot(letter)] = value;
        }
    }

    pub fn mirrors(&self, letter: u8) -> bool {
        self.mirrored & 1 << slot(letter) != 0
    }

    /// A programmed value (a coordinate or a centre offset) of `letter` as
    /// it runs: mirrored, and scaled on the linear axes (the manual scales
    /// "the shape"; a turn of a rotary axis is not a length).
    pub fn apply(&self, letter: u8, value: f64) -> f64 {
        let signed = if self.mirrors(letter) { -value } else { value };
        if matches!(letter, b'A' | b'B' | b'C') { signed } else { signed * self.scale }
    }

    /// Exactly one axis of a plane mirrored: arcs turn the other way and
    /// compensation changes side (000:5812–5814).
    pub fn flips(&self, (first, second): (u8, u8)) -> bool {
        self.mirrors(first) != self.mirrors(second)
    }
}

/// Which of the three transformations of chapter 14.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// G38.
    FirstPlanar,
    /// G39.
    SecondPlanar,
    /// G31.
    Spatial,
}

impl Kind {
    pub fn of(code: u32) -> Option<Kind> {
        match code {
            38 => Some(Kind::FirstPlanar),
            39 => Some(Kind::SecondPlanar),
            31 => Some(Kind::Spatial),
            _ => None,
        }
    }

    /// How many axes its parameter block names.
    pub fn axis_count(self) -> usize {
        match self {
            Kind::Spatial => 3,
            _ => 2,
        }
    }

    fn index(self) -> usize {
        match self {
            Kind::FirstPlanar => 0,
            Kind::SecondPlanar => 1,
            Kind::Spatial => 2,
        }
    }
}

/// A transformation's parameters: the real system's offset `a` and
/// rotation `T` against the fictive one, with `r = a + T·x` for fictive
/// `r` and real `x` (000:6377–6383).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transformation {
    /// The axes in the order written: r, s (and t); the manual does not say
    /// whether the written or the machine's order counts (03 §7 q24).
    letters: [u8; 3],
    count: usize,
    offset: Vector3<f64>,
    rotation: Matrix3<f64>,
}

impl Transformation {
    /// From the parameter block: the axes with their offsets, and the
    /// angles in degrees (I; or I, J, K for the spatial one), already
    /// divided by E. The figures with the matrices are lost (03 §7 q20):
    /// the planar rotation is the usual counter-clockwise one, the spatial
    /// one `T = Rx(α)·Ry(β)·Rz(χ)`, turning about Z first (000:6493–6514).
    pub fn new(axes: &[(u8, f64)], angles: [f64; 3]) -> Transformation {
        let mut letters = [0; 3];
        let mut offset = Vector3::zeros();
        for (i, &(letter, value)) in axes.iter().take(3).enumerate() {
            letters[i] = letter;
            offset[i] = value;
        }
        let [alpha, beta, chi] = angles.map(f64::to_radians);
        let rotation = if axes.len() == 3 {
            let turn = |axis, angle| Rotation3::from_axis_angle(&axis, angle);
            (turn(Vector3::x_axis(), alpha) * turn(Vector3::y_axis(), beta) * turn(Vector3::z_axis(), chi)).into_inner()
        } else {
            // The planar rotation in the first two components.
            Rotation3::from_axis_angle(&Vector3::z_axis(), alpha).into_inner()
        };
        Transformation { letters, count: axes.len().min(3), offset, rotation }
    }

    pub fn letters(&self) -> &[u8] {
        &self.letters[..self.count]
    }

    fn gather(&self, position: &Position) -> Vector3<f64> {
        let mut vector = Vector3::zeros();
        for (i, &letter) in self.letters().iter().enumerate() {
            vector[i] = position[slot(letter)];
        }
        vector
    }

    fn scatter(&self, vector: Vector3<f64>, position: &mut Position) {
        for (i, &letter) in self.letters().iter().enumerate() {
            position[slot(letter)] = vector[i];
        }
    }

    /// Fictive to real: `x = T⁻¹·(r − a)`.
    fn make_real(&self, position: &mut Position) {
        let real = self.rotation.transpose() * (self.gather(position) - self.offset);
        self.scatter(real, position);
    }

    /// Real to fictive: `r = a + T·x`.
    fn make_fictive(&self, position: &mut Position) {
        let fictive = self.offset + self.rotation * self.gather(position);
        self.scatter(fictive, position);
    }

    /// A fictive displacement as the real axes make it.
    fn real_displacement(&self, delta: &mut Position) {
        let real = self.rotation.transpose() * self.gather(delta);
        self.scatter(real, delta);
    }
}

/// The parameters set for each transformation of chapter 14, and which
/// are active.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Transformations {
    set: [Option<Transformation>; 3],
    active: [bool; 3],
}

/// Why a block of chapter 14 is refused.
#[derive(Debug, Clone, PartialEq)]
pub enum Refused {
    /// Parameters written while the transformation is active (000:6618).
    SetWhileActive,
    /// Activated without parameters set before (the control may have them
    /// from its backup, which the run cannot see, 000:6702).
    NotSet,
    /// An axis already in another active transformation (000:6216).
    AxisShared(u8),
    /// The parameter block names the wrong number of axes (000:6621–6626).
    AxisCount { written: usize, expected: usize },
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refused::SetWhileActive => f.write_str("its parameters cannot change while it is active"),
            Refused::NotSet => {
                f.write_str("no parameters were set for it before (the run cannot see the control's backup)")
            }
            Refused::AxisShared(letter) => {
                write!(f, "axis {} is already in another active transformation", char::from(*letter))
            }
            Refused::AxisCount { written, expected } => {
                write!(f, "its parameter block names {written} axes instead of {expected}")
            }
        }
    }
}

impl Transformations {
    pub fn set(&mut self, kind: Kind, transformation: Transformation) -> Result<(), Refused> {
        if self.active[kind.index()] {
            return Err(Refused::SetWhileActive);
        }
        let (written, expected) = (transformation.count, kind.axis_count());
        if written != expected {
            return Err(Refused::AxisCount { written, expected });
        }
        self.set[kind.index()] = Some(transformation);
        Ok(())
    }

    pub fn activate(&mut self, kind: Kind) -> Result<(), Refused> {
        let Some(transformation) = self.set[kind.index()] else { return Err(Refused::NotSet) };
        let others: Vec<&Transformation> = (0..3)
            .filter(|&index| index != kind.index() && self.active[index])
            .filter_map(|index| self.set[index].as_ref())
            .collect();
        let shared = transformation
            .letters()
            .iter()
            .find(|&&letter| others.iter().any(|other| other.letters().contains(&letter)));
        if let Some(&letter) = shared {
            return Err(Refused::AxisShared(letter));
        }
        self.active[kind.index()] = true;
        Ok(())
    }

    pub fn deactivate(&mut self, kind: Kind) {
        self.active[kind.index()] = false;
    }

    fn in_force(&self) -> impl Iterator<Item = &Transformation> {
        self.set.iter().zip(self.active).filter_map(|(set, active)| set.as_ref().filter(|_| active))
    }

    /// The active ones, as a frame keeps them.
    pub fn active(&self) -> Vec<Transformation> {
        self.in_force().copied().collect()
    }
}

/// How program coordinates become machine coordinates in one stretch of a
/// run: the translation (zero offset, G37, length correction) gives the
/// fictive machine coordinates, and the active transformations of chapter 14
/// turn those into the real ones. They never share an axis, so their order
/// does not matter.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frame {
    /// Fictive machine minus program coordinates over the machine's axes.
    pub translation: Axes,
    pub transformations: Vec<Transformation>,
}

impl Frame {
    /// Program coordinates over the machine's `axes` to real machine ones.
    pub fn to_machine(&self, values: &Axes, axes: &[u8]) -> Axes {
        let mut fictive = by_letter(values, axes);
        for (&axis, &shift) in axes.iter().zip(&self.translation) {
            fictive[slot(axis)] += shift;
        }
        for transformation in &self.transformations {
            transformation.make_real(&mut fictive);
        }
        over_axes(&fictive, axes)
    }

    /// Real machine coordinates over the machine's `axes` to program ones.
    pub fn to_program(&self, values: &Axes, axes: &[u8]) -> Axes {
        let mut position = by_letter(values, axes);
        for transformation in &self.transformations {
            transformation.make_fictive(&mut position);
        }
        for (&axis, &shift) in axes.iter().zip(&self.translation) {
            position[slot(axis)] -= shift;
        }
        over_axes(&position, axes)
    }

    /// A move's displacement by letter as the real axes make it.
    pub fn real_displacement(&self, delta: &mut Position) {
        for transformation in &self.transformations {
            transformation.real_displacement(delta);
        }
    }
}

/// Values over the machine's `axes` as a position by letter.
pub(crate) fn by_letter(values: &Axes, axes: &[u8]) -> Position {
    let mut position = [0.0; 26];
    for (&axis, &value) in axes.iter().zip(values) {
        position[slot(axis)] = value;
    }
    position
}

/// A position by letter over the machine's `axes`.
pub(crate) fn over_axes(position: &Position, axes: &[u8]) -> Axes {
    let mut values = [0.0; MAX_AXES];
    for (value, &axis) in values.iter_mut().zip(axes) {
        *value = position[slot(axis)];
    }
    values
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(actual: f64, expected: f64) {
        assert!((actual - expected).abs() < 1e-9, "{actual} != {expected}");
    }

    #[test]
    fn mirroring_and_scale_act_on_the_programmed_values() {
        let mut recalculation = Recalculation::default();
        recalculation.mirror([b'Y', b'C']);
        assert_eq!(recalculation.set_scale(&[1.54, 5.28]), Some(()));
        close(recalculation.apply(b'X', 10.0), 10.0 * 1.54 / 5.28);
        close(recalculation.apply(b'Y', 10.0), -10.0 * 1.54 / 5.28);
        close(recalculation.apply(b'C', 90.0), -90.0);
        assert!(recalculation.flips((b'X', b'Y')) && !recalculation.flips((b'Z', b'X')));
        assert_eq!(recalculation.set_scale(&[2.0, 0.0]), None);
        assert_eq!(recalculation.set_scale(&[0.0]), None);
        // A new G35 replaces the set of mirrored axes.
        recalculation.mirror([b'X']);
        assert!(recalculation.mirrors(b'X') && !recalculation.mirrors(b'Y'));
    }

    #[test]
    fn a_planar_transformation_turns_and_shifts_the_fictive_plane() {
        let transformation = Transformation::new(&[(b'X', 10.0), (b'Y', 5.0)], [90.0, 0.0, 0.0]);
        let frame = Frame { translation: [0.0; MAX_AXES], transformations: vec![transformation] };
        let axes = [b'X', b'Y', b'Z'];
        // r = a + T·x: the fictive point (10, 15) is real (10, 0) turned back.
        let real = frame.to_machine(&[10.0, 15.0, 3.0, 0.0, 0.0, 0.0], &axes);
        for (actual, expected) in real.iter().zip([10.0, 0.0, 3.0]) {
            close(*actual, expected);
        }
        let back = frame.to_program(&real, &axes);
        for (actual, expected) in back.iter().zip([10.0, 15.0, 3.0]) {
            close(*actual, expected);
        }
    }

    #[test]
    fn the_spatial_rotation_turns_about_z_first() {
        let transformation = Transformation::new(&[(b'X', 0.0), (b'Y', 0.0), (b'Z', 0.0)], [90.0, 0.0, 90.0]);
        // T = Rx(90°)·Rz(90°): the real X axis is the fictive Z axis.
        let mut position = [0.0; 26];
        position[slot(b'X')] = 1.0;
        transformation.make_fictive(&mut position);
        for (letter, expected) in [(b'X', 0.0), (b'Y', 0.0), (b'Z', 1.0)] {
            close(position[slot(letter)], expected);
        }
    }

    #[test]
    fn chapter_14_refuses_what_the_control_refuses() {
        let mut transformations = Transformations::default();
        assert_eq!(transformations.activate(Kind::FirstPlanar), Err(Refused::NotSet));
        let xz = Transformation::new(&[(b'X', 0.0), (b'Z', 0.0)], [30.0, 0.0, 0.0]);
        transformations.set(Kind::FirstPlanar, xz).unwrap();
        transformations.activate(Kind::FirstPlanar).unwrap();
        assert_eq!(transformations.set(Kind::FirstPlanar, xz), Err(Refused::SetWhileActive));
        let yz = Transformation::new(&[(b'Y', 0.0), (b'Z', 0.0)], [30.0, 0.0, 0.0]);
        transformations.set(Kind::SecondPlanar, yz).unwrap();
        assert_eq!(transformations.activate(Kind::SecondPlanar), Err(Refused::AxisShared(b'Z')));
        assert_eq!(transformations.set(Kind::Spatial, yz), Err(Refused::AxisCount { written: 2, expected: 3 }));
        transformations.deactivate(Kind::FirstPlanar);
        transformations.activate(Kind::SecondPlanar).unwrap();
        assert_eq!(transformations.active(), vec![yz]);
    }
}
