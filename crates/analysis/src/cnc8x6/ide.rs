//! What the editor answers know of CNC8x6's codes: planes, arcs, and the
//! `G79` that starts a subprogram.

use nc_exec::cnc8x6::arcs;

use crate::{
    Config,
    cnc8x6::checks::motion::PLANE_CODES,
    lower::{BlockData, Word},
};

/// Whether the machine can run the code: a plane needs both its axes.
pub(crate) fn code_fits_machine(letter: char, number: u32, config: &Config) -> bool {
    letter != 'G' || !PLANE_CODES.contains(&number) || arcs::compensation_plane(&config.machine, number).is_some()
}

/// In an arc block (G02, G03) whose plane's two axes are written, what
/// the centre words mean: I along the plane's first axis, J along its
/// second.
pub(crate) fn arc_centre(block: &BlockData, config: &Config) -> Vec<(u8, String)> {
    if !block.has_code(b'G', 2) && !block.has_code(b'G', 3) {
        return Vec::new();
    }
    let written = |axis: u8| block.word(axis).is_some();
    let Some([first, second]) = arcs::interpolation_planes(&config.machine).find(|&[a, b]| written(a) && written(b))
    else {
        return Vec::new();
    };
    let (first, second) = (char::from(first), char::from(second));
    vec![
        (b'I', format!("Arc centre along {first}, the first axis of the {first}–{second} plane")),
        (b'J', format!("Arc centre along {second}, the second axis of the {first}–{second} plane")),
    ]
}

/// Whether `word` is the code that starts a subprogram (`G79`).
pub(crate) fn starts_unit(block: &BlockData, word: &Word) -> bool {
    block.codes(b'G').any(|(code, at)| code == 79 && at.range == word.range)
}

/// The name of a subprogram with neither number nor label: its start code.
pub(crate) const UNNAMED_UNIT: &str = "G79";
