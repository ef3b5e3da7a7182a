//! A run written back as a program (`ncc expand`): what the dialects'
//! writers share. Each writer is a [`StepSink`] that writes the blocks of a
//! step as it comes, in its dialect (`cnc8x6::expand`,
//! `haas_lathe::expand`, which use this module, never the other way
//! round); the command line picks one by the program's dialect and drives
//! it as an [`Expand`], without knowing which.

use std::{fmt, io};

use ncc_syntax::TextRange;

use crate::trace::{StepSink, round3};

/// A writer of an expanded program: the steps of a run come in as a
/// [`StepSink`], and [`Expand::finish`] ends the program after the last.
pub trait Expand: StepSink {
    /// Ends the program and flushes the output; the first failure of the
    /// writing, if any.
    fn finish(self: Box<Self>) -> Result<(), ExpandError>;
}

/// A move the written program cannot express, at its block.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unwritable {
    /// The block's file, as in `Step::source`, and its range there.
    pub source: usize,
    pub range: TextRange,
    /// Why, in the dialect's terms.
    pub reason: &'static str,
}

impl fmt::Display for Unwritable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.reason)
    }
}

/// Why an expansion stopped writing.
#[derive(Debug)]
pub enum ExpandError {
    Unwritable(Unwritable),
    /// The output could not be written.
    Io(io::Error),
}

impl From<io::Error> for ExpandError {
    fn from(error: io::Error) -> ExpandError {
        ExpandError::Io(error)
    }
}

/// The offsets from the written `start` of an arc to its `centre`, to the
/// micrometre, in the plane's order: chosen among the roundings of the
/// centre so that the written `end` lies on the written circle within half
/// a micrometre, else the best of them, since a control checks the end
/// against its circle to about 1 µm.
pub(crate) fn centre_offsets(start: [f64; 2], end: [f64; 2], centre: [f64; 2]) -> [f64; 2] {
    let exact = [centre[0] - start[0], centre[1] - start[1]];
    let mismatch = |(i, j): (f64, f64)| {
        let (ci, cj) = (start[0] + i, start[1] + j);
        (i.hypot(j) - (end[0] - ci).hypot(end[1] - cj)).abs()
    };
    // The plain rounding first, then its neighbours.
    let near = |value: f64| [0.0, -0.001, 0.001].map(|delta| round3(value) + delta);
    let candidates: Vec<(f64, f64)> =
        near(exact[0]).into_iter().flat_map(|i| near(exact[1]).map(move |j| (i, j))).collect();
    let good = candidates.iter().copied().find(|&candidate| mismatch(candidate) <= 0.0005);
    let best = || candidates.iter().copied().min_by(|x, y| mismatch(*x).total_cmp(&mismatch(*y)));
    let (i, j) = good.or_else(best).unwrap_or((exact[0], exact[1]));
    [i, j]
}
