//! The program model's rules: the P/Q contour contract of G70–G73 and the
//! targets of calls and jumps (lathe manual §9 rules 27–31, 34–37, 54).

use nc_exec::haas_lathe::program::{Contour, Finding, Ignored, Monotony, Reference, ReferenceKind, RoughingType};

use crate::{Diagnostic, diagnostic::declare_rules, haas_lathe::model::FileModel};

declare_rules! {
    CONTOUR_WITHOUT_P_Q = "L027", "contour-without-p-q", Error, "G70, G71, G72 or G73 without the P or Q that names its contour's first and last block.";
    CONTOUR_TARGET_MISSING = "L028", "contour-target-missing", Error, "P or Q of G70–G73 names a block number the program does not have.";
    Q_BEFORE_P = "L029", "q-before-p", Error, "The Q block of a contour comes before its P block.";
    AMBIGUOUS_BLOCK_NUMBER = "L030", "ambiguous-block-number", Error, "P, Q, M97 P or GOTO names a block number that several blocks of the program have.";
    CONTOUR_FEED_SPEED_TOOL = "L031", "contour-feed-speed-tool", Warning, "F, S or T inside a contour P..Q: the roughing cycle does not run them.";
    TYPE_I_POCKET = "L034", "type-i-pocket", Error, "A G71 Type I contour (its P block moves one axis) that turns back in X: Type I cannot cut a pocket.";
    G72_NOT_MONOTONIC = "L035", "g72-not-monotonic", Warning, "A G72 contour that turns back in Z.";
    CONTOUR_CORNER_IGNORED = "L036", "contour-corner-ignored", Warning, "A chamfer or rounding inside the contour of G71/G72: the roughing passes leave it out.";
    CONTOUR_ANGLE_IGNORED = "L037", "contour-angle-ignored", Warning, "An angle A inside the contour of G71/G72: the roughing passes run only X and Z.";
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
    out
}

/// The reference as written, for messages: `G71 P10`, `GOTO 80`.
fn referrer(file: &FileModel, reference: Reference, number: u64) -> String {
    match reference.kind {
        ReferenceKind::ContourStart | ReferenceKind::ContourEnd => {
            let code = file.blocks[reference.block].codes(b'G').find(|c| (70..=73).contains(c)).unwrap_or(70);
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
            let cycle = file.blocks[*block].codes(b'G').find(|c| (70..=73).contains(c));
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
                        .find(|&(l, n)| file.blocks[*block].has_code(l, n))
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
                let range = file.blocks[block].number.map_or_else(Default::default, |n| file.in_file(block, n.range));
                diagnostic = diagnostic.with_related(None, range, format!("N{number}"));
            }
            out.push(diagnostic);
        }
        Finding::QBeforeP { cycle, p, q } => {
            let range = |index: usize| {
                file.blocks[index]
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
            file.blocks[block].word(monotony.axis).or(file.blocks[block].word(if axis == 'X' { b'U' } else { b'W' }));
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
            Ignored::FeedSpeedTool => {
                (&CONTOUR_FEED_SPEED_TOOL, "the roughing cycle does not run F, S or T inside its contour")
            }
            Ignored::CornerInRoughing => {
                (&CONTOUR_CORNER_IGNORED, "the roughing passes leave chamfers and roundings out; G70 cuts them")
            }
            Ignored::AngleInRoughing => (&CONTOUR_ANGLE_IGNORED, "the roughing passes run only X and Z, not the angle"),
        };
        out.push(Diagnostic::new(rule, file.in_file(ignored.block, ignored.word.range), why));
    }
}
