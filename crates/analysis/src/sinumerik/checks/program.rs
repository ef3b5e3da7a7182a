//! Rules on the program as a whole, over the program model (digest §6
//! rules 39, 40, 42, 43, 44, 47, 54, 59, 60, 68, 69, and the balance of the
//! control structures and the direction of jumps), and 51. Each is one
//! pass over the blocks or the model's lists.
//!
//! Assumptions, where the digest is silent:
//! - A program name is checked where the program writes it (its PROC line,
//!   its `%_N_…_MPF` header), not in the file's name on the host;
//!   numbered programs (`L140`) are named by their number.
//! - Rule 60 counts a structure's body as the blocks between its start and
//!   its end: a jump to the end block or to the start is no jump into it.
//! - Rules 68 and 69 read the switches in file order, the last one
//!   deciding, and report at the last block that ends the program.
//! - Rule 47 is opt-in: the digest doubts it (§8), and Siemens's own
//!   cycles end with RET under SAVE.
//! - Rule 51 reports a group-1 code a WRITE puts in a generated program
//!   from a value, `"G[01]="<<$P_GG[1]`, when no condition of the program
//!   (IF, WHILE, UNTIL, CASE) reads any of the value's variables: such a
//!   test is taken to limit the choice. A program that chooses its own
//!   motion by `G[1]=…` (a grinder's G2 or G3 from a table) is left alone.

use nc_exec::sinumerik::{
    lower::{BinaryOp, Callee, Expr, ExprKind, Jump, JumpKind, JumpTarget, Place, PlaceKind, Statement, StatementKind},
    program::{Resolved, Structure, StructureKind, Unbalanced},
};
use ncc_catalog::{AddressRole, Catalogue, Dialect};
use ncc_syntax::{TextEdit, TextRange, TextSize};

use crate::lowered::Watched;
use crate::{
    Diagnostic,
    db::Db,
    diagnostic::declare_rules,
    sinumerik::{
        checks::visit::{all_exprs, each_expr, is_transformation},
        model::FileModel,
    },
};

declare_rules! {
    AMBIGUOUS_PROGRAM_CALL = "K040", "ambiguous-program-call", Warning, "A call by the bare name of a program the workspace has both as a main program (MPF) and a subprogram (SPF): the control runs the MPF.";
    INVALID_PROGRAM_NAME = "K039", "invalid-program-name", Error, "A program name (PROC, `%_N_…_MPF`) that does not start with two letters or underscores, holds other characters than letters, digits and `_`, or is longer than 31 characters.";
    NESTING_TOO_DEEP = "K042", "nesting-too-deep", Error, "Control structures nested deeper than 16 levels.";
    PROC_NOT_FIRST = "K043", "proc-not-first", Error, "A PROC line that is not the program's first statement.";
    DEFINITION_AFTER_STATEMENT = "K044", "definition-after-statement", Error, "A DEF or EXTERN after the program's first statement that declares nothing.";
    RET_WITH_SAVE = "K047", "ret-with-save", Warning, "RET in a subprogram whose PROC line has SAVE, which the thesis says cannot be combined (Siemens's own cycles do combine them).", opt_in;
    SIMULATION_BRANCH = "K054", "simulation-branch-and-files", Info, "A program that branches on `$P_ISTEST` and writes files: a simulation started from the programming screen writes none, so the branches differ; ISFILE tests for the file itself.";
    JUMP_TARGET_NOT_FOUND = "K059", "jump-target-not-found", Error, "A jump to a label or block number the program does not have.";
    UNTESTED_MOTION_CODE = "K051", "untested-motion-code", Info, "A motion code (G group 1) that a program writes into a generated program from a value no condition tests: a 1 there is G0.";
    JUMP_INTO_STRUCTURE = "K060", "jump-into-structure", Warning, "A jump from outside into the body of an IF, WHILE, FOR, REPEAT or LOOP.";
    TRANSFORMATION_AT_END = "K068", "transformation-at-end", Warning, "The program ends with TRAORI still on (no TRAFOOF after it).";
    MODE_AT_END = "K069", "mode-at-end", Info, "The program ends with TOROT or FFWON still on (no TOROTOF or FFWOF after it).";
    UNBALANCED_STRUCTURE = "K104", "unbalanced-structure", Error, "A control structure without its end, an end without its start, or an ELSE outside an IF.";
    JUMP_WRONG_DIRECTION = "K105", "jump-wrong-direction", Error, "GOTOF to a target only behind the jump, or GOTOB to one only ahead of it.";
}

/// The deepest nesting of control structures (004:1464).
const MAX_DEPTH: usize = 16;

/// The longest program name (004:1446-1450).
const MAX_NAME_CHARS: usize = 31;

/// The word that switches TRAORI off; the other transformations' too.
pub(crate) const TRANSFORMATION_OFF: &str = "TRAFOOF";

/// The modes rule 69 wants off at the end: each the code of its group
/// that switches it on.
const MODES_OFF_AT_END: [&str; 2] = ["TOROT", "FFWON"];

/// `in_workspace`: whether the workspace holds the control file of a name
/// (`_N_PART_SPF`).
pub(crate) fn check(db: &dyn Db, file: &FileModel, in_workspace: &dyn Fn(&str) -> bool) -> Vec<Diagnostic> {
    let catalogue = Dialect::Sinumerik.catalogue();
    let mut out = Vec::new();
    names(db, catalogue, file, &mut out);
    ambiguous_calls(file, in_workspace, &mut out);
    declarations(db, file, &mut out);
    structures(file, &mut out);
    jumps(file, &mut out);
    modes_at_end(db, catalogue, file, &mut out);
    simulation_branch(db, file, &mut out);
    untested_motion_code(db, catalogue, file, &mut out);
    out
}

/// Rule 39: the names the program gives itself.
fn names(db: &dyn Db, catalogue: &Catalogue, file: &FileModel, out: &mut Vec<Diagnostic>) {
    for (index, block) in file.blocks(db).enumerate() {
        if let Some(header) = &block.header {
            let name = header.name.strip_prefix("_N_").and_then(|n| n.strip_suffix("_MPF").or(n.strip_suffix("_SPF")));
            if let Some(problem) = name.and_then(|name| name_problem(catalogue, name)) {
                out.push(Diagnostic::new(&INVALID_PROGRAM_NAME, file.in_file(index, header.range), problem));
            }
        }
        for statement in &block.statements {
            if let StatementKind::Proc(proc) = &statement.kind
                && let Some(problem) = name_problem(catalogue, &proc.name)
            {
                out.push(Diagnostic::new(&INVALID_PROGRAM_NAME, file.in_file(index, statement.range), problem));
            }
        }
    }
}

/// Rule 40: a call by the bare name finds the MPF first (004:1452-1462),
/// which a call of the subprogram does not mean.
fn ambiguous_calls(file: &FileModel, in_workspace: &dyn Fn(&str) -> bool, out: &mut Vec<Diagnostic>) {
    for site in &file.model.calls {
        let Callee::Program(name) = &site.callee else { continue };
        // A bare name looks up both kinds.
        let files = site.callee.control_files().unwrap_or_default();
        if files.len() < 2 || !files.iter().all(|file| in_workspace(file)) {
            continue;
        }
        let called = |kind: &StatementKind| match kind {
            StatementKind::Call(call) | StatementKind::ModalCall(Some(call)) => call.callee == site.callee,
            _ => false,
        };
        let statements = &file.block(site.block).statements;
        let Some(statement) = statements.iter().find(|statement| called(&statement.kind)) else { continue };
        let message = format!(
            "the workspace has {name} as a main program and a subprogram: the control runs {name}.MPF, found first; write _N_{name}_SPF to call the subprogram"
        );
        out.push(Diagnostic::new(&AMBIGUOUS_PROGRAM_CALL, file.in_file(site.block, statement.range), message));
    }
}

/// What is wrong with a program name, if anything.
fn name_problem(catalogue: &Catalogue, name: &str) -> Option<String> {
    let numbered = name.split_at_checked(1).is_some_and(|(letter, digits)| {
        catalogue.address(letter).is_some_and(|a| a.role == AddressRole::Label)
            && !digits.is_empty()
            && digits.bytes().all(|b| b.is_ascii_digit())
    });
    if numbered || name.is_empty() {
        return None;
    }
    let chars = name.chars().count();
    if chars > MAX_NAME_CHARS {
        return Some(format!("the program name {name} has {chars} characters: at most {MAX_NAME_CHARS}"));
    }
    // The thesis says two letters (004:1446); Siemens's own cycles start
    // `L_…` and `_…`, which its documentation allows: letters or `_`.
    if !name.chars().take(2).all(|c| c.is_ascii_alphabetic() || c == '_') {
        return Some(format!("the program name {name} must start with two letters or underscores"));
    }
    if let Some(bad) = name.chars().find(|c| !(c.is_ascii_alphanumeric() || *c == '_')) {
        return Some(format!("the program name {name} holds `{bad}`: only letters, digits and `_` may follow"));
    }
    None
}

/// Whether a statement declares rather than acts.
fn declares(kind: &StatementKind) -> bool {
    matches!(
        kind,
        StatementKind::Def(_) | StatementKind::Proc(_) | StatementKind::Extern(_) | StatementKind::Define { .. }
    )
}

/// Rules 43, 44 and 47.
fn declarations(db: &dyn Db, file: &FileModel, out: &mut Vec<Diagnostic>) {
    let mut first_statement = true;
    let mut acted: Option<(usize, TextRange)> = None;
    let save = file.model.header().is_some_and(|proc| proc.declaration.attributes.iter().any(|a| a == "SAVE"));
    for (index, block) in file.blocks(db).enumerate() {
        for statement in &block.statements {
            let range = file.in_file(index, statement.range);
            match &statement.kind {
                StatementKind::Proc(_) if !first_statement => {
                    let message = "PROC must be the program's first statement: the control reads the PROC line before anything else";
                    out.push(Diagnostic::new(&PROC_NOT_FIRST, range, message));
                }
                StatementKind::Def(_) | StatementKind::Extern(_) => {
                    if let Some((_, first)) = acted {
                        let keyword = if matches!(statement.kind, StatementKind::Def(_)) { "DEF" } else { "EXTERN" };
                        let message = format!(
                            "{keyword} after a statement that declares nothing: definitions come first in a program"
                        );
                        out.push(Diagnostic::new(&DEFINITION_AFTER_STATEMENT, range, message).with_related(
                            None,
                            first,
                            "the first statement",
                        ));
                    }
                }
                StatementKind::Return { .. } if save => {
                    let message = "RET in a subprogram with SAVE: RET keeps the continuous-path mode across the return while SAVE restores the caller's modal G functions, and the two cannot be combined; end the subprogram with M17";
                    out.push(Diagnostic::new(&RET_WITH_SAVE, range, message));
                }
                _ => {}
            }
            if acted.is_none() && !declares(&statement.kind) {
                acted = Some((index, range));
            }
            first_statement = false;
        }
    }
}

fn structure_name(kind: StructureKind) -> (&'static str, &'static str) {
    match kind {
        StructureKind::If => ("IF", "ENDIF"),
        StructureKind::While => ("WHILE", "ENDWHILE"),
        StructureKind::For => ("FOR", "ENDFOR"),
        StructureKind::Repeat => ("REPEAT", "UNTIL"),
        StructureKind::Loop => ("LOOP", "ENDLOOP"),
    }
}

/// The range of the statement of block `index` that opens, continues or
/// closes a structure, else the block's.
fn structure_range(file: &FileModel, index: usize) -> TextRange {
    let statement = file.block(index).statements.iter().find(|s| s.kind.is_structure());
    file.in_file(index, statement.map_or_else(TextRange::default, |s| s.range))
}

/// Rule 42 and the balance of the structures.
fn structures(file: &FileModel, out: &mut Vec<Diagnostic>) {
    if let Some(deep) = file.model.structures.iter().filter(|s| s.depth > MAX_DEPTH).min_by_key(|s| s.start) {
        let message = format!(
            "{} is nested {} levels deep: the control allows {MAX_DEPTH}",
            structure_name(deep.kind).0,
            deep.depth
        );
        out.push(Diagnostic::new(&NESTING_TOO_DEEP, structure_range(file, deep.start), message));
    }
    for unmatched in &file.model.unmatched {
        let (start, end) = structure_name(unmatched.kind);
        let message = match unmatched.problem {
            Unbalanced::NotClosed => format!("{start} without its {end}"),
            Unbalanced::NotOpened => format!("{end} without its {start}"),
            Unbalanced::StrayElse => "ELSE outside an IF, or a second ELSE of one IF".to_owned(),
        };
        out.push(Diagnostic::new(&UNBALANCED_STRUCTURE, structure_range(file, unmatched.block), message));
    }
}

fn target_text(jump: &Jump) -> String {
    match &jump.target {
        Some(JumpTarget::Label(label)) => label.clone(),
        Some(JumpTarget::BlockNumber(Some(number))) => format!("N{number}"),
        _ => String::new(),
    }
}

/// Rules 59 and 60 and the direction of jumps.
fn jumps(file: &FileModel, out: &mut Vec<Diagnostic>) {
    let enclosing = Enclosing::new(file);
    for site in &file.model.jumps {
        let range = file.in_file(site.block, site.jump.range);
        match site.resolved {
            Resolved::NotFound { alarm: true } => not_found(file, site.block, &site.jump, range, out),
            Resolved::Block(target) => {
                if let Some(structure) = enclosing.entered(target, site.block) {
                    let (start, _) = structure_name(structure.kind);
                    let message = format!(
                        "the jump to {} enters a {start} from outside it: the control has not set the structure up, so its end is reached without its start",
                        target_text(&site.jump)
                    );
                    out.push(Diagnostic::new(&JUMP_INTO_STRUCTURE, range, message).with_related(
                        None,
                        structure_range(file, structure.start),
                        format!("the {start}"),
                    ));
                }
            }
            _ => {}
        }
    }
}

/// A jump whose target is not in the direction it searches: in the other
/// direction it is the wrong keyword, else the target is missing.
fn not_found(file: &FileModel, block: usize, jump: &Jump, range: TextRange, out: &mut Vec<Diagnostic>) {
    let target = target_text(jump);
    // The keyword written, where it searches, and the one that would find
    // the target.
    let turned = match jump.kind {
        JumpKind::GotoF => Some(("GOTOF", "forward", JumpKind::GotoB, "GOTOB", "behind")),
        JumpKind::GotoB => Some(("GOTOB", "backward", JumpKind::GotoF, "GOTOF", "ahead of")),
        _ => None,
    };
    if let Some((written, searches, kind, keyword, place)) = turned
        && let Resolved::Block(found) = file.model.resolve(block, &Jump { kind, ..jump.clone() })
    {
        let message = format!("{written} searches {searches} only, and {target} is {place} the jump: write {keyword}");
        let keyword_range = TextRange::at(range.start(), TextSize::of(written));
        let diagnostic = Diagnostic::new(&JUMP_WRONG_DIRECTION, range, message)
            .with_related(None, file.in_file(found, TextRange::default()), target.clone())
            .with_fix(format!("Write {keyword}"), vec![TextEdit::replace(keyword_range, keyword)]);
        out.push(diagnostic);
        return;
    }
    let message = format!("the program has no {target} to jump to: the control stops with an alarm here");
    out.push(Diagnostic::new(&JUMP_TARGET_NOT_FOUND, range, message));
}

/// The innermost structure whose body holds each block, and each
/// structure's enclosing one: the structures nest, so a block's are a
/// chain.
struct Enclosing<'a> {
    structures: Vec<&'a Structure>,
    /// By block: the index in `structures` of the innermost one.
    innermost: Vec<Option<usize>>,
    parent: Vec<Option<usize>>,
}

impl<'a> Enclosing<'a> {
    fn new(file: &'a FileModel) -> Enclosing<'a> {
        let mut structures: Vec<&Structure> = file.model.structures.iter().collect();
        structures.sort_by_key(|s| s.depth);
        let mut innermost = vec![None; file.ranges.len()];
        let mut parent = vec![None; structures.len()];
        for (index, structure) in structures.iter().enumerate() {
            parent[index] = innermost[structure.start];
            for slot in &mut innermost[structure.start + 1..structure.end] {
                *slot = Some(index);
            }
        }
        Enclosing { structures, innermost, parent }
    }

    /// The outermost structure whose body holds `target` and not `from`.
    fn entered(&self, target: usize, from: usize) -> Option<&'a Structure> {
        let mut entered = None;
        let mut at = self.innermost[target];
        while let Some(index) = at {
            let structure = self.structures[index];
            if (structure.start..=structure.end).contains(&from) {
                break;
            }
            entered = Some(structure);
            at = self.parent[index];
        }
        entered
    }
}

/// Rule 54: `$P_ISTEST` read in a program that writes files
/// (004:3137-3143).
fn simulation_branch(db: &dyn Db, file: &FileModel, out: &mut Vec<Diagnostic>) {
    let mut tests = Vec::new();
    let mut write = None;
    for (index, block) in file.blocks(db).enumerate() {
        all_exprs(&block.statements, &mut |expr| {
            if matches!(&expr.kind, ExprKind::Name(place) if place.name == "$P_ISTEST") {
                tests.push(file.in_file(index, expr.range));
            }
        });
        let writes = |statement: &&Statement| matches!(&statement.kind, StatementKind::Call(call) if matches!(&call.callee, Callee::Predefined(name) if name == "WRITE"));
        if write.is_none()
            && let Some(statement) = block.statements.iter().find(writes)
        {
            write = Some(file.in_file(index, statement.range));
        }
    }
    let Some(write) = write else { return };
    for test in tests {
        let message = "the program branches on $P_ISTEST and writes files: a simulation started from the programming screen writes no file, so the simulated way is not the real one; the thesis tests for the written file with ISFILE (004:3137-3143)";
        out.push(Diagnostic::new(&SIMULATION_BRANCH, test, message).with_related(None, write, "WRITE"));
    }
}

/// A variable as rule 51 compares them: its name and literal indices
/// (`R7`, `$P_GG[1]`), `None` for a computed one.
type VariableKey = (String, Vec<Option<u64>>);

fn variable_key(place: &Place) -> VariableKey {
    let index = |expr: &Expr| match &expr.kind {
        ExprKind::Number(number) => number.whole(),
        _ => None,
    };
    (place.name.clone(), place.indices.iter().map(index).collect())
}

/// The variables an expression reads.
fn variables_read(expr: &Expr) -> Vec<VariableKey> {
    let mut read = Vec::new();
    each_expr(expr, &mut |expr| {
        if let ExprKind::Name(place) = &expr.kind
            && place.kind != PlaceKind::GroupCode
        {
            read.push(variable_key(place));
        }
    });
    read
}

/// The operands of a chain of `<<`, in order.
fn concatenated<'a>(expr: &'a Expr, operands: &mut Vec<&'a Expr>) {
    match &expr.kind {
        ExprKind::Binary(BinaryOp::Concat, lhs, rhs) => {
            concatenated(lhs, operands);
            concatenated(rhs, operands);
        }
        _ => operands.push(expr),
    }
}

/// Rule 51: a motion code chosen by a value no condition tests.
fn untested_motion_code(db: &dyn Db, catalogue: &Catalogue, file: &FileModel, out: &mut Vec<Diagnostic>) {
    let mut tested = rustc_hash::FxHashSet::default();
    let mut chosen: Vec<(&Expr, TextRange)> = Vec::new();
    for (index, block) in file.blocks(db).enumerate() {
        for statement in &block.statements {
            match &statement.kind {
                StatementKind::If { condition: test, .. }
                | StatementKind::While(test)
                | StatementKind::Until(test)
                | StatementKind::Case { selector: test, .. } => tested.extend(variables_read(test)),
                StatementKind::Call(call) if matches!(&call.callee, Callee::Predefined(name) if name == "WRITE") => {
                    for argument in call.arguments.iter().flatten() {
                        let mut operands = Vec::new();
                        concatenated(argument, &mut operands);
                        for pair in operands.windows(2) {
                            let ExprKind::String(text) = &pair[0].kind else { continue };
                            let text = text.trim_end().to_ascii_uppercase();
                            if text.ends_with("G[1]=") || text.ends_with("G[01]=") {
                                chosen.push((pair[1], file.in_file(index, pair[1].range)));
                            }
                        }
                    }
                }
                _ => {}
            }
        }
    }
    let first = catalogue.code_at("G1", 1).map_or("G0", |code| code.code.as_str());
    for (value, range) in chosen {
        let read = variables_read(value);
        if read.is_empty() || read.iter().any(|variable| tested.contains(variable)) {
            continue;
        }
        let message = format!(
            "the motion code of the program written here is chosen by a value no condition tests: a 1 there selects {first}, as happened to the thesis's generated program (004:3331-3347); test that it is 2 (G1) or a spline's index first"
        );
        out.push(Diagnostic::new(&UNTESTED_MOTION_CODE, range, message));
    }
}

/// Rules 68 and 69: the switches still on at the last block that ends
/// the program.
fn modes_at_end(db: &dyn Db, catalogue: &Catalogue, file: &FileModel, out: &mut Vec<Diagnostic>) {
    let mut transformation: Option<(String, TextRange)> = None;
    let groups: Vec<Option<&str>> =
        MODES_OFF_AT_END.iter().map(|word| catalogue.word_code(word).and_then(|c| c.group.as_deref())).collect();
    let mut modes: Vec<Option<TextRange>> = vec![None; MODES_OFF_AT_END.len()];
    let mut at_end = None;
    for (index, block) in file.blocks(db).enumerate() {
        for statement in &block.statements {
            let StatementKind::Command(command) = &statement.kind else { continue };
            let range = file.in_file(index, statement.range);
            if is_transformation(&command.name) {
                transformation = (command.name != TRANSFORMATION_OFF).then(|| (command.name.clone(), range));
            }
            let Some(code) = catalogue.word_code(&command.name) else { continue };
            for (slot, (word, group)) in modes.iter_mut().zip(MODES_OFF_AT_END.iter().zip(&groups)) {
                if code.group.as_deref().is_some_and(|g| Some(g) == *group) {
                    *slot = (code.code == *word).then_some(range);
                }
            }
        }
        if block.program_end().is_some() {
            let end = file.in_file(index, block.statements.last().map_or_else(TextRange::default, |s| s.range));
            at_end = Some((end, transformation.clone(), modes.clone()));
        }
    }
    let Some((end, transformation, modes)) = at_end else { return };
    if let Some((name, on)) = transformation {
        let message = format!("the program ends with {name} still on: write {TRANSFORMATION_OFF} before the end");
        out.push(Diagnostic::new(&TRANSFORMATION_AT_END, end, message).with_related(None, on, name));
    }
    for (word, on) in MODES_OFF_AT_END.iter().zip(modes) {
        if let Some(on) = on {
            let message = format!("the program ends with {word} still on");
            out.push(Diagnostic::new(&MODE_AT_END, end, message).with_related(None, on, word.to_string()));
        }
    }
}
