//! Sinumerik's programmable frame: how the commands TRANS/ATRANS,
//! ROT/AROT, SCALE/ASCALE and MIRROR/AMIRROR move the coordinate system
//! the program writes in against the settable frame (G54, …) below it
//! (digest §2.2, 004:1338-1364).
//!
//! ```text
//! let mut frame = ProgrammableFrame::default();
//! frame.apply(FrameCommand::from_name("ATRANS").unwrap(), &[("X", 55.0), ("Y", 4.0)], Plane::XY)?;
//! frame.apply(FrameCommand::from_name("ASCALE").unwrap(), &[("X", 0.18), ("Y", 0.18)], Plane::XY)?;
//! let base = frame.to_base([100.0, 0.0, 0.0]); // [73.0, 4.0, 0.0]
//! ```
//!
//! The frame is an affine map on X, Y and Z from program to base
//! coordinates. The thesis says only that the A-forms are additive and the
//! plain ones absolute (004:1354-1356); the readings taken:
//! - an absolute command replaces the whole programmable frame by its own
//!   component, so `TRANS` without words clears it (Siemens documentation);
//! - an additive command acts in the coordinates in force: the frame
//!   becomes the old one after the new component, so an ATRANS after an
//!   ASCALE is scaled and an ATRANS after an AROT runs along the turned
//!   axes (Siemens documentation; Annex 2 scales and then translates,
//!   004:3847-3849, 3933-3935);
//! - `ROT Z45` turns by 45° about Z, counter-clockwise looking down the
//!   axis (the right-hand rule); `RPL=` turns about the normal of the
//!   active plane (Z under G17, Y under G18, X under G19);
//! - several axes in one ROT turn about Z first, then about the turned Y,
//!   then about the twice turned X: the roll-pitch-yaw order of Siemens's
//!   default frame angle input (machine data FRAME_ANGLE_INPUT_MODE = 1,
//!   Siemens documentation recalled, not in the thesis);
//! - SCALE and ASCALE scale each axis written and leave the others at 1; a
//!   factor of 0 is refused, as it would flatten the part;
//! - `MIRROR X0` reverses X; the value only names the axis (Siemens
//!   documentation), and mirroring an axis twice restores it;
//! - the rotary axes (A, B, C) are not part of the frame: a word for one is
//!   refused, and their positions pass unchanged (their angular offsets
//!   are left to the settable frames).

use std::fmt;

use nalgebra::{Matrix3, Rotation3, Vector3};

/// The working plane (G17, G18, G19): which axes an arc turns in and
/// which one the tool points along.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Plane {
    /// G17: X/Y, the tool along Z.
    #[default]
    XY,
    /// G18: Z/X, the tool along Y.
    ZX,
    /// G19: Y/Z, the tool along X.
    YZ,
}

impl Plane {
    /// The plane a code selects: `G17`, `G18`, `G19`.
    pub fn from_code(code: &str) -> Option<Plane> {
        match code.to_ascii_uppercase().as_str() {
            "G17" => Some(Plane::XY),
            "G18" => Some(Plane::ZX),
            "G19" => Some(Plane::YZ),
            _ => None,
        }
    }

    /// The indices (0 = X) of the abscissa, the ordinate and the tool axis:
    /// a right-handed triple, so a turn about the tool axis runs from the
    /// abscissa to the ordinate.
    pub fn axes(self) -> [usize; 3] {
        match self {
            Plane::XY => [0, 1, 2],
            Plane::ZX => [2, 0, 1],
            Plane::YZ => [1, 2, 0],
        }
    }
}

/// What a frame command does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameKind {
    Translation,
    Rotation,
    Scale,
    Mirror,
}

/// A frame command: its component, and whether it adds to the frame in
/// force (`ATRANS`) or replaces it (`TRANS`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameCommand {
    pub kind: FrameKind,
    pub additive: bool,
}

impl FrameCommand {
    /// The command named `name` (any case): `TRANS`, `ATRANS`, `ROT`,
    /// `AROT`, `SCALE`, `ASCALE`, `MIRROR`, `AMIRROR`.
    pub fn from_name(name: &str) -> Option<FrameCommand> {
        let name = name.to_ascii_uppercase();
        let (additive, base) = match name.strip_prefix('A') {
            Some(rest) => (true, rest),
            None => (false, name.as_str()),
        };
        let kind = match base {
            "TRANS" => FrameKind::Translation,
            "ROT" => FrameKind::Rotation,
            "SCALE" => FrameKind::Scale,
            "MIRROR" => FrameKind::Mirror,
            _ => return None,
        };
        Some(FrameCommand { kind, additive })
    }
}

/// Why a frame command was refused; `word` is the index of the word at
/// fault in the words given to [`ProgrammableFrame::apply`].
#[derive(Debug, Clone, PartialEq)]
pub struct FrameError {
    pub word: usize,
    pub kind: FrameErrorKind,
}

#[derive(Debug, Clone, PartialEq)]
pub enum FrameErrorKind {
    /// An address that is not X, Y or Z (nor RPL for a rotation).
    NotAFrameAxis(String),
    /// `RPL=` with a command other than ROT/AROT, or with axis words.
    PlaneRotation,
    /// The same axis twice in one command.
    Repeated(String),
    ScaleZero(String),
    NotFinite(String),
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.kind {
            FrameErrorKind::NotAFrameAxis(address) => {
                write!(f, "{address} is not an axis of the programmable frame: X, Y and Z (RPL for a rotation)")
            }
            FrameErrorKind::PlaneRotation => {
                f.write_str("RPL= turns in the plane with ROT or AROT only, and without axis words")
            }
            FrameErrorKind::Repeated(axis) => write!(f, "{axis} is written twice in one frame command"),
            FrameErrorKind::ScaleZero(axis) => write!(f, "a scale of 0 on {axis} would flatten the part"),
            FrameErrorKind::NotFinite(address) => write!(f, "{address} has no finite value"),
        }
    }
}

impl std::error::Error for FrameError {}

/// An affine map x ↦ linear·x + translation.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Affine {
    linear: Matrix3<f64>,
    translation: Vector3<f64>,
}

impl Affine {
    const IDENTITY: Affine = Affine {
        linear: Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        translation: Vector3::new(0.0, 0.0, 0.0),
    };

    fn linear(linear: Matrix3<f64>) -> Affine {
        Affine { linear, translation: Vector3::zeros() }
    }

    /// `self` after `inner`: x ↦ self(inner(x)).
    fn after(&self, inner: &Affine) -> Affine {
        Affine { linear: self.linear * inner.linear, translation: self.linear * inner.translation + self.translation }
    }

    fn map(&self, point: [f64; 3]) -> [f64; 3] {
        (self.linear * Vector3::from(point) + self.translation).into()
    }
}

/// The programmable frame in force: from program to base coordinates
/// (those of the settable frame), and back; and its components as
/// programmed, for display.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgrammableFrame {
    to_base: Affine,
    /// Kept alongside as the product of the components' exact inverses,
    /// so that mapping back never inverts a matrix.
    to_program: Affine,
    /// The rotations composed, the scale factors of each program axis in
    /// the order written, and the axes mirrored an odd number of times.
    rotation: Rotation3<f64>,
    scales: [Vec<f64>; 3],
    mirrored: [bool; 3],
}

impl Default for ProgrammableFrame {
    fn default() -> Self {
        ProgrammableFrame {
            to_base: Affine::IDENTITY,
            to_program: Affine::IDENTITY,
            rotation: Rotation3::identity(),
            scales: Default::default(),
            mirrored: [false; 3],
        }
    }
}

const AXES: [&str; 3] = ["X", "Y", "Z"];

impl ProgrammableFrame {
    /// Runs `command` with its `words` (address, value) under `plane`. A
    /// refused command leaves the frame as it was.
    pub fn apply(&mut self, command: FrameCommand, words: &[(&str, f64)], plane: Plane) -> Result<(), FrameError> {
        let values = axis_values(command, words, plane)?;
        if !command.additive {
            *self = ProgrammableFrame::default();
        }
        self.compose(command.kind, values);
        Ok(())
    }

    /// Adds the component `kind` of the values of X, Y and Z (`None` for an
    /// axis not written) on top of the frame, as an additive command does.
    /// The values must be finite, and a scale's not zero.
    pub(super) fn compose(&mut self, kind: FrameKind, values: [Option<f64>; 3]) {
        let (component, inverse) = match kind {
            FrameKind::Translation => {
                let shift = Vector3::from(values.map(|value| value.unwrap_or(0.0)));
                let along = |translation| Affine { linear: Matrix3::identity(), translation };
                (along(shift), along(-shift))
            }
            FrameKind::Rotation => {
                let [x, y, z] = values.map(|value| value.unwrap_or(0.0).to_radians());
                // Rz·Ry·Rx: about Z first, then the turned Y, then X.
                let rotation = Rotation3::from_euler_angles(x, y, z);
                self.rotation *= rotation;
                (Affine::linear(*rotation.matrix()), Affine::linear(*rotation.inverse().matrix()))
            }
            FrameKind::Scale => {
                for (scales, value) in self.scales.iter_mut().zip(values) {
                    scales.extend(value);
                }
                let factors = Vector3::from(values.map(|value| value.unwrap_or(1.0)));
                let inverse = factors.map(|factor| 1.0 / factor);
                (Affine::linear(Matrix3::from_diagonal(&factors)), Affine::linear(Matrix3::from_diagonal(&inverse)))
            }
            FrameKind::Mirror => {
                for (mirrored, value) in self.mirrored.iter_mut().zip(values) {
                    *mirrored ^= value.is_some();
                }
                let signs = Vector3::from(values.map(|value| if value.is_some() { -1.0 } else { 1.0 }));
                let mirror = Affine::linear(Matrix3::from_diagonal(&signs));
                (mirror, mirror)
            }
        };
        self.to_base = self.to_base.after(&component);
        self.to_program = inverse.after(&self.to_program);
    }

    /// A point in program coordinates, in base coordinates.
    pub fn to_base(&self, program: [f64; 3]) -> [f64; 3] {
        self.to_base.map(program)
    }

    /// A point in base coordinates, in program coordinates.
    pub fn to_program(&self, base: [f64; 3]) -> [f64; 3] {
        self.to_program.map(base)
    }

    /// A direction (or a difference of points) in program coordinates, in
    /// base coordinates.
    pub fn direction_to_base(&self, program: [f64; 3]) -> [f64; 3] {
        (self.to_base.linear * Vector3::from(program)).into()
    }

    /// Whether the frame is the identity: no programmable frame in force.
    pub fn is_identity(&self) -> bool {
        *self == ProgrammableFrame::default()
    }

    /// Whether an arc programmed in `plane` stays a circular arc in the same
    /// plane of the base coordinates: the frame maps the plane's axes into
    /// that plane, at right angles and by the same factor (a turn about the
    /// tool axis, a uniform scale in the plane, mirrors). Where not, the
    /// arc becomes an ellipse or leaves the plane, and must be run as a
    /// curve of short lines.
    pub fn keeps_plane(&self, plane: Plane) -> bool {
        let [abscissa, ordinate, normal] = plane.axes();
        let (a, o) = (self.to_base.linear.column(abscissa), self.to_base.linear.column(ordinate));
        let scale = a.norm().max(o.norm());
        let small = 1e-9 * scale;
        a[normal].abs() <= small
            && o[normal].abs() <= small
            && (a.norm() - o.norm()).abs() <= small
            && a.dot(&o).abs() <= small * scale
    }

    /// Whether an arc programmed in `plane` runs the other way round in the
    /// base coordinates (G2 becomes G3): an odd number of the plane's axes
    /// are mirrored, or a half turn about an axis in the plane turned it
    /// over.
    pub fn turns_arcs_over(&self, plane: Plane) -> bool {
        let [abscissa, ordinate, _] = plane.axes();
        let m = &self.to_base.linear;
        let determinant =
            m[(abscissa, abscissa)] * m[(ordinate, ordinate)] - m[(abscissa, ordinate)] * m[(ordinate, abscissa)];
        determinant < 0.0
    }

    /// The scale factors of each axis composed: X, Y, Z.
    pub fn scale(&self) -> [f64; 3] {
        std::array::from_fn(|axis| self.scales[axis].iter().product())
    }
}

/// The value of each axis X, Y, Z that `words` write, in that order; a
/// rotation in the plane as one about its tool axis.
fn axis_values(command: FrameCommand, words: &[(&str, f64)], plane: Plane) -> Result<[Option<f64>; 3], FrameError> {
    let mut values = [None; 3];
    let mut in_plane = false;
    for (index, &(address, value)) in words.iter().enumerate() {
        let error = |kind| Err(FrameError { word: index, kind });
        let address = address.to_ascii_uppercase();
        if !value.is_finite() {
            return error(FrameErrorKind::NotFinite(address));
        }
        if address == "RPL" {
            if command.kind != FrameKind::Rotation || values.iter().any(Option::is_some) {
                return error(FrameErrorKind::PlaneRotation);
            }
            in_plane = true;
            values[plane.axes()[2]] = Some(value);
            continue;
        }
        let Some(axis) = AXES.iter().position(|&name| name == address) else {
            return error(FrameErrorKind::NotAFrameAxis(address));
        };
        if in_plane {
            return error(FrameErrorKind::PlaneRotation);
        }
        if values[axis].is_some() {
            return error(FrameErrorKind::Repeated(address));
        }
        if command.kind == FrameKind::Scale && value == 0.0 {
            return error(FrameErrorKind::ScaleZero(address));
        }
        values[axis] = Some(value);
    }
    Ok(values)
}

/// The composed frame for hover: `translation X14.5 Y4, scale
/// X0.18·0.75 Y0.18·0.75 Z0.18`; the translation is where the program
/// zero lies in base coordinates, the rotation the angles about X, Y and Z
/// in the order of [`ProgrammableFrame::apply`], the scale each program
/// axis's factors as written.
impl fmt::Display for ProgrammableFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_identity() {
            return f.write_str("no programmable frame");
        }
        let mut parts = Vec::new();
        let words = |values: [f64; 3], neutral: f64| {
            AXES.iter()
                .zip(values)
                .filter(|&(_, value)| (value - neutral).abs() > 1e-9)
                .map(|(axis, value)| format!("{axis}{}", number(value)))
                .collect::<Vec<_>>()
        };
        let translation = words(self.to_base.translation.into(), 0.0);
        if !translation.is_empty() {
            parts.push(format!("translation {}", translation.join(" ")));
        }
        let (x, y, z) = self.rotation.euler_angles();
        let rotation = words([x, y, z].map(f64::to_degrees), 0.0);
        if !rotation.is_empty() {
            parts.push(format!("rotation {}", rotation.join(" ")));
        }
        let scales: Vec<String> = AXES
            .iter()
            .zip(&self.scales)
            .filter(|(_, factors)| !factors.is_empty())
            .map(|(axis, factors)| {
                format!("{axis}{}", factors.iter().map(|&f| number(f)).collect::<Vec<_>>().join("·"))
            })
            .collect();
        if !scales.is_empty() {
            parts.push(format!("scale {}", scales.join(" ")));
        }
        let mirrored: Vec<&str> = AXES.iter().zip(self.mirrored).filter(|(_, on)| *on).map(|(axis, _)| *axis).collect();
        if !mirrored.is_empty() {
            parts.push(format!("mirror {}", mirrored.join(" ")));
        }
        if parts.is_empty() {
            // Components that cancel: a turn and its reverse, a scale by 1.
            return f.write_str("no programmable frame");
        }
        f.write_str(&parts.join(", "))
    }
}

/// A value to four decimals, without trailing zeros.
fn number(value: f64) -> String {
    let text = format!("{:.4}", value);
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" { "0".to_owned() } else { text.to_owned() }
}

#[cfg(test)]
mod tests;
