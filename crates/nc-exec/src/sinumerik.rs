//! The Siemens Sinumerik dialect's part of the executor: its block IR and
//! lowering ([`lower`]), the program model over the lowered blocks
//! ([`program`]), values and expressions ([`eval`]), the programmable
//! frame ([`frames`]), the drilling and swivel cycles ([`cycles`]), the
//! velocity policy with the continuous-path modes ([`dynamics`]), the
//! interpreter that runs a program (`interpreter`, which the run driver
//! picks) and the run written back as plain blocks ([`expand`]).
//!
//! What reads them:
//!
//! - The interpreter runs [`lower::SinumerikBlock::statements`] in order:
//!   words (address, literal or expression, `AC`/`IC`), assignments to R
//!   parameters, variables, system variables and `G[n]`, commands with
//!   the words a frame takes, calls with their arguments and repetitions,
//!   and expressions as trees whose operators the parser already ordered.
//!   It follows [`program::SinumerikModel`]: where each structure's start,
//!   ELSE and end lead ([`program::SinumerikModel::structures_at`]), each
//!   jump's block, the labels and block numbers a computed target
//!   (`"N"<<R3`) is looked up in with [`program::SinumerikModel::resolve`],
//!   and the PROC header that binds a call's arguments to the formal
//!   parameters (omitted ones are zero, 004:1480-1484).
//! - The checker reads the same model over partly unknown values: the
//!   unbalanced control structures, jumps without a target, labels and
//!   block numbers written twice, and calls against the PROC and EXTERN
//!   signatures by argument count.

pub mod cycles;
pub mod dynamics;
pub mod eval;
pub mod expand;
pub mod frames;
pub(crate) mod interpreter;
pub mod lower;
pub mod modes;
pub mod program;

pub use interpreter::Unit;

/// The tool and edge of a machine configuration's tool offset key
/// `T<t>D<d>` (`T1D1`), both from 1.
pub fn cutting_edge_key(key: &str) -> Option<(u32, u32)> {
    let rest = key.strip_prefix(['T', 't'])?;
    let (tool, edge) = rest.split_once(['D', 'd'])?;
    let number = |text: &str| {
        text.bytes().all(|byte| byte.is_ascii_digit()).then(|| text.parse().ok()).flatten().filter(|&n| n > 0)
    };
    Some((number(tool)?, number(edge)?))
}
