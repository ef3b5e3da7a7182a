//! The P/Q contour contract of G70–G73 and the targets of calls and jumps
//! (lathe manual §9 rules 27–32, 34–42, 54): from the program model, and
//! from the walk where the cycle's start point matters.

use nc_exec::{
    haas_lathe::{
        lower::Value,
        program::{Contour, Finding, Ignored, Monotony, Reference, ReferenceKind, RoughingType},
    },
    known::Known,
};
use ncc_catalog::Dialect;

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    haas_lathe::{
        checks::Out,
        model::FileModel,
        walk::{COMPENSATION, Kind, MOTION, Visit},
    },
};

declare_rules! {
    CONTOUR_WITHOUT_P_Q = "L027", "contour-without-p-q", Error, "G70, G71, G72 or G73 without the P or Q that names its contour's first and last block.";
    CONTOUR_TARGET_MISSING = "L028", "contour-target-missing", Error, "P or Q of G70–G73 names a block number the program does not have.";
    Q_BEFORE_P = "L029", "q-before-p", Error, "The Q block of a contour comes before its P block.";
    AMBIGUOUS_BLOCK_NUMBER = "L030", "ambiguous-block-number", Error, "P, Q, M97 P or GOTO names a block number that several blocks of the program have.";
    CONTOUR_FEED_SPEED_TOOL = "L031", "contour-feed-speed-tool", Warning, "F, S or T inside a contour P..Q: the cycles G70–G73 do not run them.";
    NO_FINISHING_PASS = "L032", "no-finishing-pass", Info, "A roughing cycle G71–G73 that no later G70 finishes.";
    TYPE_I_POCKET = "L034", "type-i-pocket", Error, "A G71 Type I contour (its P block moves one axis) that turns back in X: Type I cannot cut a pocket.";
    G72_NOT_MONOTONIC = "L035", "g72-not-monotonic", Warning, "A G72 contour that turns back in Z.";
    CONTOUR_CORNER_IGNORED = "L036", "contour-corner-ignored", Warning, "A chamfer or rounding inside the contour of G71/G72: the roughing passes leave it out.";
    CONTOUR_ANGLE_IGNORED = "L037", "contour-angle-ignored", Warning, "An angle A inside the contour of G71/G72: the roughing passes run only X and Z.";
    ALLOWANCE_SIGN = "L039", "allowance-sign", Warning, "The sign of a roughing cycle's U (or I) says the other side than its start point: + outside (OD), − inside (ID).";
    START_INSIDE_CONTOUR = "L040", "start-inside-contour", Warning, "A roughing cycle whose start point lies inside the contour's extent, where the first infeed starts.";
    NON_CONTOUR_CONTENT = "L041", "non-contour-content", Warning, "A code inside a contour P..Q other than a move (G00–G03) or tool-nose compensation (G40–G42).";
    CONTOUR_START_NOT_LINEAR = "L042", "contour-start-not-linear", Warning, "A contour whose P block is not a G00/G01 move.";
    M97_TARGET_MISSING = "L054", "m97-target-missing", Error, "M97 P names a block number the program does not have.";
    CALL_WITHOUT_P = "L101", "call-without-p", Error, "M97, M98 or G65 without the P that names what it calls.";
    GOTO_TARGET_MISSING = "L102", "goto-target-missing", Error, "GOTO names a block number the program does not have.";
}

/// The findings of the program model.
pub(crate) fn check(file: &FileModel) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for finding in &file.model.findings {
        model_finding(file, finding, &mut out);
    }
    finishing(file, &mut out);
    content(file, &mut out);
    out
}

/// Rule 32: roughing without a finishing pass is legal (001:1556-1559),
/// worth a hint. A G70 without roughing is legal too, and not flagged
/// (rule 33).
fn finishing(file: &FileModel, out: &mut Vec<Diagnostic>) {
    let contours: Vec<&Contour> = file.model.contours().collect();
    for rough in contours.iter().filter(|contour| contour.code != 70) {
        let program = file.model.program_of(rough.cycle).map(|program| &program.blocks);
        let finished = contours.iter().any(|finish| {
            finish.code == 70
                && finish.cycle > rough.cycle
                && finish.blocks == rough.blocks
                && program.is_some_and(|blocks| blocks.contains(&finish.cycle))
        });
        // Without allowances the roughing is the finish.
        let allowance: Vec<String> = [b'U', b'W']
            .into_iter()
            .filter_map(|letter| file.block(rough.cycle).word(letter))
            .filter(|word| !matches!(&word.value, Some(Value::Literal(decimal)) if decimal.to_f64() == 0.0))
            .map(ToString::to_string)
            .collect();
        if !finished && !allowance.is_empty() {
            let message = format!(
                "no later G70 finishes this G{} contour: the allowance {} stays on the part",
                rough.code,
                allowance.join(" ")
            );
            out.push(Diagnostic::new(&NO_FINISHING_PASS, file.code_range(rough.cycle, b'G', rough.code), message));
        }
    }
}

/// Rule 41: a contour is the part's shape; every example holds only moves
/// and compensation (001:1560, 1807-1817, 1879-1887).
fn content(file: &FileModel, out: &mut Vec<Diagnostic>) {
    let catalogue = Dialect::HaasLathe.catalogue();
    let is_cycle = |code: u32| catalogue.cycles_for(&format!("G{code:02}")).next().is_some();
    let mut seen = Vec::new();
    for contour in file.model.contours() {
        if seen.contains(&contour.blocks) {
            continue;
        }
        seen.push(contour.blocks.clone());
        for index in contour.blocks.clone() {
            let block = file.block(index);
            let codes = block.code_words(b'G').map(|(code, word)| ('G', code, word));
            for (letter, code, word) in codes.chain(block.code_words(b'M').map(|(code, word)| ('M', code, word))) {
                let group = catalogue.group_of(letter, code).map(|group| group.id.as_str());
                let shape = letter == 'G' && matches!(group, Some(MOTION | COMPENSATION)) && !is_cycle(code);
                if !shape {
                    let message = format!(
                        "{letter}{code:02} inside the contour: a contour is the part's shape, moves (G00–G03) and compensation (G40–G42) only; what the cycle does with {letter}{code:02} the manual does not say"
                    );
                    out.push(Diagnostic::new(&NON_CONTOUR_CONTENT, file.in_file(index, word.range), message));
                }
            }
        }
    }
}

/// Rules 39, 40 and 42, at a cycle block whose contour the walk ran.
pub(crate) fn visit(visit: &Visit<'_>, out: &mut Out) {
    let (Kind::Cycle(code), Some(run)) = (visit.kind, visit.run) else { return };
    let Some(contour) = visit.file.model.contours().find(|contour| contour.cycle == visit.index) else { return };
    let p = *contour.blocks.start();
    let bent = match run.p_kind {
        Some(Kind::Move(Known::Is(motion))) => motion > 1,
        Some(Kind::Still | Kind::Cycle(_) | Kind::Drill) => true,
        Some(Kind::Move(Known::Unknown) | Kind::Other) | None => false,
    };
    if bent {
        let message = "the contour's first block is not a G00/G01 move: the cycle's first infeed runs to it from the start point (every example starts the contour with G00)";
        let diagnostic = Diagnostic::new(&CONTOUR_START_NOT_LINEAR, visit.file.number_range(p), message).with_related(
            None,
            visit.code_range(code),
            format!("G{code}"),
        );
        out.push(diagnostic);
    }
    if code == 70 {
        return;
    }
    let (Known::Is(x), Known::Is(z)) = (visit.before.x, visit.before.z) else { return };
    let xs = run.feed_points.iter().map(|&(x, _)| x);
    let (Some(min), Some(max)) = (xs.clone().reduce(f64::min), xs.reduce(f64::max)) else { return };
    let Some(top) = run.feed_points.iter().map(|&(_, z)| z).reduce(f64::max) else { return };
    let at = visit.code_range(code);
    // Between the contour's smallest and largest X the start is inside
    // whichever side is cut; outside them the side is known for rule 39.
    if min < x && x < max {
        let message = format!(
            "the start point X{x} lies between the contour's smallest X{min} and largest X{max}: the first infeed starts inside the stock"
        );
        out.push(Diagnostic::new(&START_INSIDE_CONTOUR, at, message));
    }
    if z < top {
        let message = format!(
            "the start point Z{z} is not beyond the contour, which reaches Z{top}: the first infeed starts inside the stock"
        );
        out.push(Diagnostic::new(&START_INSIDE_CONTOUR, at, message));
    }
    let outside = if x >= max && x > min {
        Some(true)
    } else if x <= min && x < max {
        Some(false)
    } else {
        None
    };
    let Some(outside) = outside else { return };
    for letter in [b'U', b'I'] {
        let Some(word) = visit.block.word(letter) else { continue };
        let Known::Is(value) = visit.before.number(word) else { continue };
        if value != 0.0 && (value > 0.0) != outside {
            let letter = char::from(letter);
            let (marked, side, edge, sign) = if outside {
                ("an inside (ID)", "outside the contour (largest X", max, "an outside (OD) cut takes it positive")
            } else {
                ("an outside (OD)", "inside the contour (smallest X", min, "an inside (ID) cut takes it negative")
            };
            let message =
                format!("{letter}{value} marks {marked} cut, but the start point X{x} lies {side}{edge}): {sign}");
            out.push(Diagnostic::new(&ALLOWANCE_SIGN, visit.range(word), message));
        }
    }
}

/// The reference as written, for messages: `G71 P10`, `GOTO 80`.
fn referrer(file: &FileModel, reference: Reference, number: u64) -> String {
    match reference.kind {
        ReferenceKind::ContourStart | ReferenceKind::ContourEnd => {
            let code = file.block(reference.block).codes(b'G').find(|c| (70..=73).contains(c)).unwrap_or(70);
            let letter = if reference.kind == ReferenceKind::ContourStart { 'P' } else { 'Q' };
            format!("G{code} {letter}{number}")
        }
        ReferenceKind::LocalCall => format!("M97 P{number}"),
        ReferenceKind::ProgramCall => format!("M98 P{number}"),
        ReferenceKind::MacroCall => format!("G65 P{number}"),
        ReferenceKind::Goto => format!("GOTO {number}"),
    }
}

fn model_finding(file: &FileModel, finding: &Finding, out: &mut Vec<Diagnostic>) {
    match finding {
        Finding::MissingAddress { block, letter } => {
            let cycle = file.block(*block).codes(b'G').find(|c| (70..=73).contains(c));
            let letter = char::from(*letter);
            let diagnostic = match cycle {
                Some(code) => Diagnostic::new(
                    &CONTOUR_WITHOUT_P_Q,
                    file.code_range(*block, b'G', code),
                    format!(
                        "G{code} needs {letter}: the block number of the contour's {} block",
                        if letter == 'P' { "first" } else { "last" }
                    ),
                ),
                None => {
                    let (code_letter, number) = [(b'M', 97), (b'M', 98), (b'G', 65)]
                        .into_iter()
                        .find(|&(l, n)| file.block(*block).has_code(l, n))
                        .unwrap_or((b'M', 98));
                    Diagnostic::new(
                        &CALL_WITHOUT_P,
                        file.code_range(*block, code_letter, number),
                        format!("{}{number:02} needs P: the block or program number it calls", char::from(code_letter)),
                    )
                }
            };
            out.push(diagnostic);
        }
        Finding::TargetNotFound { reference, number } => {
            let rule = match reference.kind {
                ReferenceKind::LocalCall => &M97_TARGET_MISSING,
                ReferenceKind::Goto => &GOTO_TARGET_MISSING,
                _ => &CONTOUR_TARGET_MISSING,
            };
            let message = format!("{}: no block N{number} in this program", referrer(file, *reference, *number));
            out.push(Diagnostic::new(rule, file.reference_range(*reference), message));
        }
        Finding::AmbiguousTarget { reference, number, blocks } => {
            let message = format!(
                "{}: {} blocks are numbered N{number}; the control takes the first",
                referrer(file, *reference, *number),
                blocks.len()
            );
            let mut diagnostic = Diagnostic::new(&AMBIGUOUS_BLOCK_NUMBER, file.reference_range(*reference), message);
            for &block in blocks {
                let range = file.block(block).number.map_or_else(Default::default, |n| file.in_file(block, n.range));
                diagnostic = diagnostic.with_related(None, range, format!("N{number}"));
            }
            out.push(diagnostic);
        }
        Finding::QBeforeP { cycle, p, q } => {
            let range = |index: usize| {
                file.block(index)
                    .number
                    .map_or_else(|| file.in_file(index, Default::default()), |n| file.in_file(index, n.range))
            };
            let diagnostic = Diagnostic::new(
                &Q_BEFORE_P,
                file.word_range(*cycle, b'Q').unwrap_or_else(|| range(*cycle)),
                "the contour's last block (Q) comes before its first (P): P names the first block, Q the last",
            )
            .with_related(None, range(*p), "the P block")
            .with_related(None, range(*q), "the Q block");
            out.push(diagnostic);
        }
        Finding::Contour(contour) => contour_findings(file, contour, out),
        Finding::ComputedTarget(_) | Finding::Resolved { .. } => {}
    }
}

fn contour_findings(file: &FileModel, contour: &Contour, out: &mut Vec<Diagnostic>) {
    if let Some(monotony) = contour.monotony
        && let Monotony::Reverses { block } = monotony.monotony
    {
        let axis = char::from(monotony.axis);
        let cycle = file.code_range(contour.cycle, b'G', contour.code);
        let at =
            file.block(block).word(monotony.axis).or(file.block(block).word(if axis == 'X' { b'U' } else { b'W' }));
        let range = at.map_or(cycle, |w| file.in_file(block, w.range));
        let diagnostic = if contour.roughing_type == Some(RoughingType::TypeI) {
            Diagnostic::new(
                &TYPE_I_POCKET,
                range,
                "the contour turns back in X here, a pocket G71 Type I cannot cut; program Z (or W) in the P block too for Type II",
            )
        } else {
            Diagnostic::new(
                &G72_NOT_MONOTONIC,
                range,
                "the contour turns back in Z here; the manual documents G72 for contours that do not",
            )
        };
        out.push(diagnostic.with_related(None, cycle, format!("the G{} cycle", contour.code)));
    }
    for ignored in &contour.ignored {
        let (rule, why) = match ignored.why {
            Ignored::FeedSpeedTool => (
                &CONTOUR_FEED_SPEED_TOOL,
                "the cycle does not run F, S or T inside its contour; give F in the cycle's block",
            ),
            Ignored::CornerInRoughing => {
                (&CONTOUR_CORNER_IGNORED, "the roughing passes leave chamfers and roundings out; G70 cuts them")
            }
            Ignored::AngleInRoughing => (&CONTOUR_ANGLE_IGNORED, "the roughing passes run only X and Z, not the angle"),
        };
        out.push(Diagnostic::new(rule, file.in_file(ignored.block, ignored.word.range), why));
    }
}
