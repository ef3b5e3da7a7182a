//! Fixed cycles G81–G89: calls, their parameters and the cycle file.
//!
//! What G81–G89 do depends on the cycle file the control loads (`$17` of
//! CNC836.KNF, `machine.cycle-file` in ncc.toml): the milling file drills,
//! the lathe files rough and cut threads. Without that setting the rules
//! assume one of the supplied files and report only what holds for both;
//! with a file of the user's own they check only how cycles are called.

use ncc_catalog::{Dialect, Flavour, Modality};
use ncc_syntax::{Severity, TextEdit, TextRange, TextSize};

use crate::{
    Config, Diagnostic,
    cnc8x6::checks::{motion, params::show, structure},
    cnc8x6::flow::{FlowCheck, ModalState, Origin, Visit},
    cnc8x6::model::{self, FileKind},
    db::{Db, SourceFile},
    diagnostic::declare_rules,
};

declare_rules! {
    CALL_WITHOUT_POSITION = "C801", "cycle-call-without-position", Warning, "A drilling cycle called in a block that only sets parameters or M functions, without a position.";
    REPEATS_WITHOUT_MOTION = "C802", "cycle-repeats-without-motion", Warning, "A block without motion while a fixed cycle is active, which runs the cycle again in place.";
    ACTIVE_AT_PROGRAM_END = "C803", "cycle-active-at-program-end", Warning, "M02 or M30 while a fixed cycle is still active.";
    IN_INCREMENTAL_MODE = "C804", "cycle-in-incremental-mode", Warning, "G83, which does not switch to G90 itself, running under G91.";
    FILE_DIAMETER_MISMATCH = "C805", "cycle-file-diameter-mismatch", Info, "A lathe cycle under G74 or G75 while the cycle file is made for the other X programming.";
    PARAMETER_UNASSIGNED = "C806", "cycle-parameter-unassigned", Warning, "A fixed cycle called before the program assigns a parameter it reads.";
    INVALID_PARAMETER = "C807", "invalid-cycle-parameter", Error, "A cycle parameter the cycle cannot work with: a zero step, a quotient, chip count or sign out of range.";
    RETRACT_TOWARD_PART = "C808", "cycle-retract-toward-part", Warning, "Lathe G87 whose passes end beyond the start X, so its retract moves toward the part.";
    FILE_MISSING_KEYWORD = "C809", "cycle-file-missing-keyword", Error, "A fixed-cycle file without the `$PC` keyword at its start or the `*` at its end.";
}

/// The G groups of the fixed cycle, the distance mode (G90/G91) and the X
/// programming (G74/G75).
const CYCLE_GROUP: usize = 8;
const DISTANCE_GROUP: usize = 9;
const X_PROGRAMMING_GROUP: usize = 10;

/// How a lathe cycle file reads X sizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum XProgramming {
    Diameter,
    Radius,
}

/// A cycle file supplied with the control. The catalogue describes the
/// cycles of PCYKLYDG.NCP and PEVNECY5.NCP; PEVNECY6.NCP has the same
/// cycles for radius programming, PEVNECY4.NCP has no alternating thread
/// infeed and is edited by hand for either X programming. Older files
/// (PEVNECYK.NCP, without plane R32) count as the user's own.
struct SuppliedFile {
    stem: &'static str,
    flavour: Flavour,
    x: Option<XProgramming>,
    alternating_infeed: bool,
}

const SUPPLIED_FILES: [SuppliedFile; 4] = [
    SuppliedFile { stem: "PCYKLYDG", flavour: Flavour::Milling, x: None, alternating_infeed: false },
    SuppliedFile { stem: "PEVNECY4", flavour: Flavour::Lathe, x: None, alternating_infeed: false },
    SuppliedFile {
        stem: "PEVNECY5",
        flavour: Flavour::Lathe,
        x: Some(XProgramming::Diameter),
        alternating_infeed: true,
    },
    SuppliedFile { stem: "PEVNECY6", flavour: Flavour::Lathe, x: Some(XProgramming::Radius), alternating_infeed: true },
];

/// What the configured cycle file tells about G81–G89.
#[derive(Clone, Copy)]
enum Loaded {
    /// No `machine.cycle-file`: one of the supplied files.
    Unconfigured,
    Supplied(&'static SuppliedFile),
    /// A file of the user's own: its cycles are unknown.
    Own,
}

impl Loaded {
    fn of(config: &Config) -> Loaded {
        let Some(name) = config.machine.cycle_file.as_deref() else { return Loaded::Unconfigured };
        let stem = model::file_stem(name);
        SUPPLIED_FILES.iter().find(|file| file.stem.eq_ignore_ascii_case(stem)).map_or(Loaded::Own, Loaded::Supplied)
    }

    /// The flavours G81–G89 may have.
    fn flavours(self) -> &'static [Flavour] {
        match self {
            Loaded::Unconfigured => &[Flavour::Milling, Flavour::Lathe],
            Loaded::Supplied(file) => std::slice::from_ref(&file.flavour),
            Loaded::Own => &[],
        }
    }

    fn flavour(self) -> Option<Flavour> {
        match self {
            Loaded::Supplied(file) => Some(file.flavour),
            _ => None,
        }
    }

    fn alternating_infeed(self) -> bool {
        matches!(self, Loaded::Supplied(file) if file.alternating_infeed)
    }
}

#[derive(Default)]
pub(crate) struct Cycles {
    /// Where the code last written in each G group was, to point at the
    /// call of the active cycle or the block that set G91 or G74.
    written: [Option<(u32, TextRange)>; 12],
}

impl FlowCheck for Cycles {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        let call = visit.codes.iter().find(|&&(letter, code, _)| letter == b'G' && (81..=89).contains(&code));
        // G80 with a cycle in one block is a group conflict, reported as such.
        if !(call.is_some() && visit.has_code(b'G', 80))
            && let Some(Some(code @ 81..=89)) = visit.after.g(CYCLE_GROUP)
        {
            self.cycle_runs(visit, code, call.map(|&(_, _, range)| range), out);
        }
        self.remember(visit);
    }
}

impl Cycles {
    /// The checks of a block in which cycle `code` runs; `call` is where
    /// the block calls it, if it does.
    fn cycle_runs(&self, visit: &Visit<'_>, code: u32, call: Option<TextRange>, out: &mut Vec<Diagnostic>) {
        let called_at = call.or_else(|| self.written(visit.before, CYCLE_GROUP));
        let end = visit.codes.iter().find(|&&(letter, n, _)| letter == b'M' && matches!(n, 2 | 30));
        let moves = motion::moves(visit);
        if let Some(&(_, end_code, end_range)) = end {
            out.push(with_call(
                Diagnostic::new(
                    &ACTIVE_AT_PROGRAM_END,
                    end_range,
                    format!("G{code} is still active at the program end, so the cycle may run once more in this block; cancel it with G80 before the end"),
                )
                .with_fix(format!("Insert G80 before M{end_code:02}"), vec![TextEdit::replace(TextRange::empty(end_range.start()), "G80 ")]),
                called_at.filter(|_| call.is_none()),
                code,
            ));
        } else if call.is_none() && !moves {
            out.push(with_call(
                Diagnostic::new(
                    &REPEATS_WITHOUT_MOTION,
                    head(visit),
                    format!("G{code} is still active, so it runs again in this block at the same position, because the block does not move; write G80 in this block (or earlier) when the cycle is done"),
                ),
                called_at,
                code,
            ));
        }
        let loaded = Loaded::of(visit.config);
        if let Some(call) = call {
            // Drilling cycles drill where the calling block ends; lathe
            // cycles start wherever the tool stands, and G88/G89 are empty
            // slots for the user's own cycles.
            let setup_only = !visit.block.assignments.is_empty() || visit.codes.iter().any(|&(l, _, _)| l == b'M');
            if loaded.flavour() == Some(Flavour::Milling) && (81..=87).contains(&code) && !moves && setup_only {
                out.push(Diagnostic::new(
                    &CALL_WITHOUT_POSITION,
                    call,
                    format!("G{code} drills where its block ends, but this block has no position: it drills where the tool already stands, and again in the next block if that does not move; write G{code} in the block that moves to the first hole (e.g. `X50. Y20. G{code}`)"),
                ));
            }
            self.check_x_programming(visit, loaded, code, call, out);
            check_unassigned(visit, loaded, code, call, out);
        }
        self.check_incremental(visit, loaded, code, call, out);
        check_values(visit, loaded, code, call, called_at, out);
        if code == 87 && loaded.flavour() == Some(Flavour::Lathe) {
            check_retract(visit, call, out);
        }
    }

    /// Milling and lathe G83 take their planes in the distance mode of the
    /// caller: under G91 they drill from the current Z by R30 and R31.
    fn check_incremental(
        &self,
        visit: &Visit<'_>,
        loaded: Loaded,
        code: u32,
        call: Option<TextRange>,
        out: &mut Vec<Diagnostic>,
    ) {
        let incremental = |state: &ModalState| state.has_g(DISTANCE_GROUP, 91);
        let already = visit.before.has_g(CYCLE_GROUP, 83) && incremental(visit.before);
        if code != 83 || loaded.flavours().is_empty() || !incremental(visit.after) || already {
            return;
        }
        let g91 = visit.code_range(b'G', 91).or_else(|| self.written(visit.before, DISTANCE_GROUP));
        let g83 = call.or_else(|| self.written(visit.before, CYCLE_GROUP));
        let range = call.or_else(|| visit.code_range(b'G', 91)).unwrap_or_else(|| head(visit));
        let mut diagnostic = Diagnostic::new(
            &IN_INCREMENTAL_MODE,
            range,
            "G83 does not switch to absolute dimensions (G90) as the other cycles do, so under G91 it takes its planes R30 and R31 as distances from the current Z; program G90 while the cycle is active, moves between the holes included",
        );
        if let Some(g91) = g91.filter(|&g91| g91 != range) {
            diagnostic = diagnostic.with_related(None, g91, "G91 set here");
        }
        if let Some(g83) = g83.filter(|&g83| g83 != range) {
            diagnostic = diagnostic.with_related(None, g83, "G83 called here");
        }
        out.push(diagnostic);
    }

    /// A lathe cycle file made for diameter or radius programming, called
    /// under the other one.
    fn check_x_programming(
        &self,
        visit: &Visit<'_>,
        loaded: Loaded,
        code: u32,
        call: TextRange,
        out: &mut Vec<Diagnostic>,
    ) {
        let (Loaded::Supplied(file), Some(name)) = (loaded, visit.config.machine.cycle_file.as_deref()) else { return };
        let (made_for, active, active_name, wanted, other) = match (file.x, visit.after.g(X_PROGRAMMING_GROUP)) {
            (Some(XProgramming::Diameter), Some(Some(75))) => ("diameter", 75, "radius", 74, "PEVNECY6.NCP"),
            (Some(XProgramming::Radius), Some(Some(74))) => ("radius", 74, "diameter", 75, "PEVNECY5.NCP"),
            _ => return,
        };
        let mut diagnostic = Diagnostic::new(
            &FILE_DIAMETER_MISMATCH,
            call,
            format!(
                "the machine's cycle file {name} is made for {made_for} programming, but G{active} ({active_name} programming) is active: G{code} would take the start X and its X sizes (R24, R28, R30) wrong by a factor of 2; program G{wanted} or load {other}"
            ),
        );
        let set = visit.code_range(b'G', active).or_else(|| self.written(visit.before, X_PROGRAMMING_GROUP));
        if let Some(set) = set.filter(|&set| set != call) {
            diagnostic = diagnostic.with_related(None, set, format!("G{active} set here"));
        }
        out.push(diagnostic);
    }

    /// Remembers where the block wrote modal G codes.
    fn remember(&mut self, visit: &Visit<'_>) {
        let catalogue = Dialect::Cnc8x6.catalogue();
        for &(_, code, range) in visit.codes.iter().filter(|&&(letter, _, _)| letter == b'G') {
            let modal = catalogue.code('G', code).is_some_and(|c| c.modality == Modality::Modal);
            let group = catalogue.group_of('G', code).and_then(|g| ncc_catalog::split_code(&g.id));
            if let (true, Some((_, index))) = (modal, group)
                && let Some(slot) = self.written.get_mut(index as usize)
            {
                *slot = Some((code, range));
            }
        }
    }

    /// Where the code active in G group `group` of `state` was written, if
    /// this walk saw it.
    fn written(&self, state: &ModalState, group: usize) -> Option<TextRange> {
        let (code, range) = self.written[group]?;
        state.has_g(group, code).then_some(range)
    }
}

/// Points a diagnostic at the call of the active cycle.
fn with_call(diagnostic: Diagnostic, called_at: Option<TextRange>, code: u32) -> Diagnostic {
    match called_at {
        Some(range) => diagnostic.with_related(None, range, format!("G{code} called here")),
        None => diagnostic,
    }
}

/// Where diagnostics about the whole block point: its first word.
fn head(visit: &Visit<'_>) -> TextRange {
    visit.block.words.first().map_or(visit.range(TextRange::default()), |w| visit.range(w.range))
}

/// Whether the block runs parameter arithmetic (G26–G29), whose order
/// against the cycle the manual does not give: its parameters are then not
/// known for the cycle.
fn has_arithmetic(visit: &Visit<'_>) -> bool {
    (26..=29).any(|code| visit.has_code(b'G', code))
}

/// A cycle input as the cycle reads it: after the block's assignments.
fn input(visit: &Visit<'_>, r: u32) -> Option<(i64, Option<Origin>)> {
    if has_arithmetic(visit) {
        return None;
    }
    visit.params_after.get(r)
}

/// The parameters cycle `code` reads whatever file is loaded: those that
/// every possible flavour's cycle reads.
fn certain_inputs(loaded: Loaded, code: u32) -> Vec<u32> {
    let catalogue = Dialect::Cnc8x6.catalogue();
    let name = format!("G{code}");
    let mut cycles = loaded.flavours().iter().map(|&f| catalogue.cycles_for(&name).find(|c| c.flavour == f));
    let Some(Some(first)) = cycles.next() else { return Vec::new() };
    let mut inputs: Vec<u32> = first.parameters.iter().map(|p| p.r).collect();
    for cycle in cycles {
        inputs.retain(|r| cycle.is_some_and(|c| c.parameters.iter().any(|p| p.r == *r)));
    }
    inputs
}

/// Whether this call reads input `r` of a lathe thread cycle that only
/// some set-ups read.
fn read_by_this_call(visit: &Visit<'_>, loaded: Loaded, r: u32) -> bool {
    match r {
        // The alternating infeed (PEVNECY5/6) reads R21 and, when R21 is
        // not 0, the flank allowance R19.
        21 => loaded.alternating_infeed(),
        19 => loaded.alternating_infeed() && input(visit, 21).is_some_and(|(raw, _)| raw != 0),
        // G33 reads the run-out angle from R04 when machine constant 8
        // (decades 8–7) names it.
        4 => visit.config.machine.decade(8, 8) * 10 + visit.config.machine.decade(8, 7) == 4,
        _ => true,
    }
}

fn check_unassigned(visit: &Visit<'_>, loaded: Loaded, code: u32, call: TextRange, out: &mut Vec<Diagnostic>) {
    if !visit.params.from_start || has_arithmetic(visit) {
        return;
    }
    let missing: Vec<String> = certain_inputs(loaded, code)
        .into_iter()
        .filter(|&r| read_by_this_call(visit, loaded, r))
        .filter(|&r| visit.params_after.origins.get(r as usize).is_some_and(Option::is_none))
        .map(|r| format!("R{r}"))
        .collect();
    let message = match missing.as_slice() {
        [] => return,
        [one] => format!(
            "G{code} reads {one}, which the program has not assigned before this call: the cycle uses whatever an earlier program left in it; assign it ({one}=…) before the call or in this block"
        ),
        [rest @ .., last] => format!(
            "G{code} reads {} and {last}, which the program has not assigned before this call: the cycle uses whatever an earlier program left in them; assign them before the call or in this block",
            rest.join(", ")
        ),
    };
    out.push(Diagnostic::new(&PARAMETER_UNASSIGNED, call, message));
}

/// A parameter value a cycle cannot work with.
struct Finding {
    /// The parameters involved, the one to change first.
    params: Vec<u32>,
    severity: Severity,
    message: String,
}

impl Finding {
    fn error(params: &[u32], message: String) -> Finding {
        Finding { params: params.to_vec(), severity: Severity::Error, message }
    }

    fn warning(params: &[u32], message: String) -> Finding {
        Finding { params: params.to_vec(), severity: Severity::Warning, message }
    }
}

/// The value constraints of cycle `code` (raw values: thousandths of a
/// millimetre for lengths, the count itself for counts).
fn findings(loaded: Loaded, code: u32, value: impl Fn(u32) -> Option<i64>) -> Vec<Finding> {
    let mut found = Vec::new();
    let step = value(28);
    // Both supplied G83s peck by R28.
    if code == 83 && !loaded.flavours().is_empty() && step == Some(0) {
        found.push(Finding::error(&[28], "R28 = 0: G83 pecks by R28, so the drill never gets deeper and the cycle repeats until its loop count runs out; give the peck depth, e.g. R28=5.".into()));
    }
    match (loaded.flavour(), code) {
        (Some(Flavour::Milling), 86) => {
            if step == Some(0) {
                found.push(Finding::error(&[28], "R28 = 0: G86 drills in steps of R28, so the drill never gets deeper and the cycle repeats until its loop count runs out; give the step, e.g. R28=5.".into()));
            }
            if let (Some(step), Some(top), Some(bottom)) = (step, value(30), value(31)) {
                let depth = (bottom - top).abs();
                if depth > 0 && step.abs() > depth {
                    found.push(Finding::warning(&[28, 30, 31], format!("the step |R28| = {} mm is larger than the hole depth |R31 - R30| = {} mm: G86 makes no feed step and reaches the bottom in rapid (G00); make R28 at most the depth", show(step.abs()), show(depth))));
                }
            }
        }
        (Some(Flavour::Lathe), 81 | 82) => {
            match step {
                Some(0) => found.push(Finding::error(&[28], "R28 = 0: the chips never get thicker and the finishing pass divides by R28; give the chip thickness, e.g. R28=2.".into())),
                Some(negative) if negative < 0 => {
                    let direction = if code == 81 { "R30" } else { "R31" };
                    found.push(Finding::warning(&[28], format!("R28 = {}: the cycle takes the direction from {direction} itself, so a negative chip thickness moves the chips away from the final size and the roughing repeats until its loop count runs out; write R28 positive", show(negative))));
                }
                _ => {}
            }
            if value(30) == Some(0) {
                found.push(Finding::error(&[30], "R30 = 0: the roughing region has no size in X; give its size with the sign of the direction (e.g. R30=-20.)".into()));
            }
            if value(31) == Some(0) {
                found.push(Finding::error(&[31], "R31 = 0: the roughing region has no length in Z; give its length with the sign of the direction (e.g. R31=-40.)".into()));
            }
        }
        (Some(Flavour::Lathe), 83) => {
            if let Some(negative) = step.filter(|&s| s < 0) {
                found.push(Finding::warning(&[28], format!("R28 = {}: lathe G83 does not take the absolute value of the peck depth, so a negative R28 pecks away from the hole bottom; write it positive", show(negative))));
            }
        }
        (Some(Flavour::Lathe), 84 | 85 | 87) => {
            if let Some(quotient) = step.filter(|q| !(1..1000).contains(q)) {
                let why = match quotient {
                    1000 => "the cycle divides by zero when it sums the series of chip depths",
                    q if q > 1000 => "every chip would be deeper than the one before",
                    _ => "the first chip would take the whole thread depth, the others none or less than none",
                };
                found.push(Finding::error(&[28], format!("R28 = {}: {why}; the quotient of the chip depths must lie strictly between 0 and 1 (0.8 is usual)", show(quotient))));
            }
            match value(29) {
                Some(chips) if chips <= 1 => found.push(Finding::error(&[29], format!("R29 = {chips}: a thread needs at least 2 chips; the chip loop repeats R29 - 2 times, which is negative here"))),
                Some(2) => found.push(Finding::warning(&[29], "R29 = 2 gives the chip loop a repeat count of 0, which the manual does not define; use 3 or more chips, or check the cycle at the machine".into())),
                _ => {}
            }
            // R20 = 0 or 60 is the metric thread, as written with or without a point.
            let alternating = value(21).is_some_and(|infeed| infeed != 0);
            let metric = value(20).is_none_or(|kind| matches!(kind, 0 | 60 | 60_000));
            if code != 87 && loaded.alternating_infeed() && alternating && !metric {
                found.push(Finding::warning(&[20, 21], "R20 asks for a thread other than metric, but the cycle implements only the metric thread: with alternating infeed (R21 not 0) it cuts the flanks for a metric thread anyway".into()));
            }
            if code == 85
                && let Some(runout) = value(22).filter(|&r| r <= 0)
            {
                found.push(Finding::warning(&[22], format!("R22 = {}: the run-out length must be positive; every pass takes it as the J of its G33, and the thread length R31 includes it", show(runout))));
            }
        }
        (Some(Flavour::Lathe), 86) => {
            for (r, axis) in [(30, "X"), (31, "Z")] {
                if value(r) == Some(0) {
                    found.push(Finding::warning(&[r], format!("R{r} = 0: G86 divides by the chamfer length in {axis}; give the chamfer length (e.g. R{r}=3.)")));
                }
            }
            match (step, value(30)) {
                (Some(0), _) => found.push(Finding::warning(&[28], "R28 = 0: the passes never get deeper, so G86 repeats the first pass until its loop count runs out; give the chip thickness, e.g. R28=1.".into())),
                (Some(chip), Some(length)) if length != 0 && chip.abs() > length.abs() => found.push(Finding::warning(&[28, 30], format!("the chip |R28| = {} mm is thicker than the chamfer |R30| = {} mm, so the first pass cuts deeper than the chamfer; make R28 at most |R30|", show(chip.abs()), show(length.abs())))),
                _ => {}
            }
        }
        _ => {}
    }
    found
}

/// Parameter values against the cycle's constraints: at the call, and in
/// the blocks that run the cycle again with a parameter they assign.
fn check_values(
    visit: &Visit<'_>,
    loaded: Loaded,
    code: u32,
    call: Option<TextRange>,
    called_at: Option<TextRange>,
    out: &mut Vec<Diagnostic>,
) {
    let assigned_here = |r: u32| visit.block.assignments.iter().find(|a| a.index == Some(r));
    for finding in findings(loaded, code, |r| input(visit, r).map(|(raw, _)| raw)) {
        let range = match call {
            Some(call) => call,
            None => match finding.params.iter().find_map(|&r| assigned_here(r)) {
                Some(assignment) => visit.range(assignment.range),
                None => continue,
            },
        };
        let mut diagnostic = Diagnostic::new(&INVALID_PARAMETER, range, finding.message);
        diagnostic.severity = finding.severity;
        for &r in &finding.params {
            if let Some((_, Some(origin))) =
                input(visit, r).filter(|(_, o)| o.is_some_and(|o| !range.contains_range(o.range)))
            {
                let how = if origin.computed { "computed" } else { "assigned" };
                diagnostic = diagnostic.with_related(None, origin.range, format!("R{r} {how} here"));
            }
        }
        if call.is_none() {
            diagnostic = with_call(diagnostic, called_at, code);
        }
        out.push(diagnostic);
    }
}

/// Lathe G87 cuts each pass from X_j to X_j + R22 and retracts straight
/// to the start X; the retract must move away from the part, against the
/// infeed (the sign of R30), also after the shallowest, first pass.
fn check_retract(visit: &Visit<'_>, call: Option<TextRange>, out: &mut Vec<Diagnostic>) {
    let value = |r| input(visit, r).map(|(raw, _)| raw);
    let start = visit.reached.get(usize::from(b'X' - b'A')).and_then(|p| p.known());
    let (Some(start), Some(rise), Some(offset), Some(quotient), Some(chips), Some(depth)) =
        (start, value(22), value(24), value(28), value(29), value(30))
    else {
        return;
    };
    // Values the cycle cannot work with are `invalid-cycle-parameter`.
    if !(1..1000).contains(&quotient) || chips < 2 || depth == 0 {
        return;
    }
    let Ok(chips) = i32::try_from(chips) else { return };
    let k = quotient as f64 / 1000.0;
    let first_chip = depth.abs() as f64 * (1.0 - k) / (1.0 - k.powi(chips));
    let infeed = depth.signum() as f64;
    let first_end = (start + offset) as f64 + infeed * first_chip + rise as f64;
    // Half a micrometre of slack for the rounding of the chip series.
    if infeed * (start as f64 - first_end) <= 0.5 {
        return;
    }
    let x_word = visit.block.word(b'X').map(|w| visit.range(w.range));
    let range = call.or(x_word).unwrap_or_else(|| head(visit));
    let mut diagnostic = Diagnostic::new(
        &RETRACT_TOWARD_PART,
        range,
        format!(
            "the first pass ends at X{:.3} (start + R24 + first chip + taper rise R22), beyond the start X{}: after every pass G87 retracts in rapid straight to X{}, which moves toward the part; start farther out in X or check the sign of R22",
            first_end / 1000.0,
            show(start),
            show(start)
        ),
    );
    if let Some((_, Some(origin))) = input(visit, 22) {
        diagnostic = diagnostic.with_related(None, origin.range, "taper rise R22 set here");
    }
    out.push(diagnostic);
}

/// The `$PC` keyword and the `*` end of the fixed-cycle file.
pub(crate) fn check_file(db: &dyn Db, file: SourceFile) -> Vec<Diagnostic> {
    let program = model::program(db, file);
    if program.kind != FileKind::CycleFile {
        return Vec::new();
    }
    let mut out = Vec::new();
    // Without `$PC` the file is a cycle file only because the machine
    // configuration names it.
    if FileKind::of(file.path(db), model::prelude(db, file)) != FileKind::CycleFile {
        out.push(
            Diagnostic::new(
                &FILE_MISSING_KEYWORD,
                structure::file_start(db, file),
                "this is the machine's cycle file, but it does not start with the keyword `$PC`: the control loads a fixed-cycle file only with `$PC` in its first line (usually in a comment, `\"$PC - FIXED CYCLES`)",
            )
            .with_fix("Insert a first line with `$PC`", vec![TextEdit::replace(TextRange::empty(TextSize::from(0)), "\"  $PC\n")]),
        );
    }
    let (_, has_end) = model::header_and_end(db, file);
    if !has_end {
        let text = file.text(db);
        let end = TextSize::from(text.len() as u32);
        let range = program
            .get_block(program.block_count().wrapping_sub(1))
            .map_or_else(|| structure::file_start(db, file), |b| b.head);
        let insert = if text.is_empty() || text.ends_with('\n') { "*\n" } else { "\n*\n" };
        out.push(
            Diagnostic::new(
                &FILE_MISSING_KEYWORD,
                range,
                "a fixed-cycle file ends with `*` after its last cycle body; without it the control does not load the file",
            )
            .with_fix("Append the `*` that ends the file", vec![TextEdit::replace(TextRange::empty(end), insert)]),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::{AnalysisHost, Config, Diagnostic};

    fn diagnostics(config: &str, path: &str, text: &str) -> Vec<Diagnostic> {
        let mut host = AnalysisHost::new(
            Config::from_toml(config, "ncc.toml".as_ref(), |path| std::fs::read_to_string(path)).unwrap(),
        );
        let file = host.add_file(path, text);
        host.analysis().diagnostics(file)
    }

    fn apply(text: &str, diagnostic: &Diagnostic) -> String {
        let mut text = text.to_owned();
        for edit in &diagnostic.fixes[0].edits {
            edit.apply(&mut text);
        }
        text
    }

    #[test]
    fn fixes_complete_the_cycle_file() {
        let config = "[machine]\ncycle-file = \"PCYKLYDG.NCP\"\n";
        let text = "N1 G79 L81\nN2 G00 G90 ZR30 FR26 SR27\nN3 G01 ZR31\nN4 G00 G70 ZR32";
        let found = diagnostics(config, "PCYKLYDG.NCP", text);
        let names: Vec<_> = found.iter().map(|d| d.name).collect();
        assert_eq!(names, ["cycle-file-missing-keyword", "cycle-file-missing-keyword"], "{found:#?}");
        let fixed = apply(&apply(text, &found[1]), &found[0]);
        assert_eq!(fixed, format!("\"  $PC\n{text}\n*\n"));
        assert!(diagnostics(config, "PCYKLYDG.NCP", &fixed).is_empty());
    }

    #[test]
    fn g80_fix_cancels_the_cycle_before_the_end() {
        let text = "%1\nN10 G90 G80 T1 M06\nN20 R26=100 R27=800 R30=2. R31=-10. R32=5.\nN30 G00 X10. Y10. S800 M03\nN40 X20. G81\nN50 M30\n*\n";
        let found = diagnostics("", "main.NCP", text);
        let end = found.iter().find(|d| d.name == "cycle-active-at-program-end").expect("reported");
        let fixed = apply(text, end);
        assert!(fixed.contains("N50 G80 M30\n"));
        assert!(diagnostics("", "main.NCP", &fixed).is_empty(), "{:#?}", diagnostics("", "main.NCP", &fixed));
    }
}
