//! Rules on single blocks, from their statements alone (digest §6 rules 4,
//! 7, 49, 50, 53, 55, 56, 57, 79, 80 and the comparison priority). They run per
//! chunk of blocks, so an edit checks again only the chunk it touched.

use nc_exec::sinumerik::lower::{BinaryOp, Callee, Expr, ExprKind, PlaceKind, SinumerikBlock, StatementKind};
use ncc_catalog::{Catalogue, Dialect};
use ncc_syntax::{TextEdit, TextRange, TextSize};

use crate::{
    Config, Diagnostic,
    config::CycleVersion,
    diagnostic::declare_rules,
    sinumerik::{
        MAX_BLOCK_CHARS,
        checks::visit::{all_exprs, number, statement_exprs, written_places},
    },
};

declare_rules! {
    BLOCK_TOO_LONG = "K004", "block-too-long", Error, "A block longer than the 512 characters the control reads.";
    SAME_GROUP_IN_BLOCK = "K007", "same-group-in-block", Error, "Two codes of one modal group in a block (`G0 G1`, `G90 G91`, `BSPLINE G1`).";
    R_PARAMETER_OUT_OF_RANGE = "K049", "r-parameter-out-of-range", Error, "An R parameter beyond the control's count, where `[sinumerik] r-parameters` gives it (machine data $MN_MM_NUM_R_PARAM).";
    GROUP_NUMBER_NOT_CODE = "K050", "group-number-not-code", Warning, "`G[n]=1` where the group's first code is not G1: `G[1]=1` selects G0.";
    SYNC_ACTION_SHARES_BLOCK = "K055", "sync-action-shares-block", Error, "A synchronous action (`ID=1 WHENEVER … DO …`) with other statements in its block.";
    NUL_IN_STRING = "K056", "nul-in-string", Info, "A string with a NUL character, where the control cuts it off.";
    TOOL_VARIABLE_UNDER_MANAGEMENT = "K053", "tool-variable-under-management", Warning, "`$P_TOOLNO` or `$P_TOOLP` on a machine with tool management (`[sinumerik] tool-management`), where GETEXET and GETSELT give the tool.";
    CYCLE832_OPTION = "K057", "cycle832-option", Hint, "CYCLE832 needs its option on the control; without it, its expansion does the same.";
    INTERPOLATING_SPLINE = "K079", "interpolating-spline", Info, "ASPLINE or CSPLINE, which pass through every point: on digitised or noisy points BSPLINE, which approximates them, is smoother.";
    SPLINE_PARAMETER_RANGE = "K080", "spline-parameter-range", Error, "A spline degree SD other than 2 or 3, or a point weight PW outside 0 to 3.";
    CYCLE_ARGUMENTS_FOR_VERSION = "K058", "cycle-arguments-for-version", Info, "A cycle call with more arguments than the cycle takes in the version `[sinumerik] cycle-version` names: the argument lists differ between versions.";
    COMPARISON_PRIORITY = "K107", "comparison-priority", Warning, "A comparison with an unparenthesised AND, OR, XOR or `<<` as operand: Sinumerik ranks comparisons below them, so `A>5 AND B<3` reads `A>(5 AND B)<3`.";
}

/// What CYCLE832 switches on, written out (004:3302-3308).
const CYCLE832_EXPANSION: &str = "SOFT DYNFINISH COMPCAD G645 FIFOCTRL FFWON";

/// The system variables that do not give the tool under tool management,
/// and what does (004:3274-3280).
const TOOL_VARIABLES: [(&str, &str); 2] = [("$P_TOOLNO", "GETEXET"), ("$P_TOOLP", "GETSELT")];

/// The splines that pass through their points (004:3488-3491).
const INTERPOLATING_SPLINES: [&str; 2] = ["ASPLINE", "CSPLINE"];

/// The findings of one block; `text` is the block's, and ranges are
/// relative to its start.
pub(crate) fn check(block: &SinumerikBlock, text: &str, config: &Config) -> Vec<Diagnostic> {
    let catalogue = Dialect::Sinumerik.catalogue();
    let mut out = Vec::new();
    length(text, &mut out);
    groups(catalogue, block, &mut out);
    r_parameters(block, config, &mut out);
    statements(catalogue, block, &mut out);
    spline_words(block, &mut out);
    if config.sinumerik.tool_management {
        tool_variables(block, &mut out);
    }
    if let Some(version) = config.sinumerik.cycle_version {
        cycle_arguments(catalogue, block, version, &mut out);
    }
    for statement in &block.statements {
        statement_exprs(statement, &mut |expr| priority(text, expr, &mut out));
    }
    out
}

/// Rule 58: a call of a cycle with more arguments than its list in
/// `version` has; trailing ones may be left out.
fn cycle_arguments(catalogue: &Catalogue, block: &SinumerikBlock, version: CycleVersion, out: &mut Vec<Diagnostic>) {
    // The catalogue's lists are the classic ones.
    let CycleVersion::Classic = version;
    for statement in &block.statements {
        let StatementKind::Call(call) = &statement.kind else { continue };
        let Callee::Cycle(name) = &call.callee else { continue };
        let Some(cycle) = catalogue.cycles_for(name).find(|cycle| !cycle.arguments.is_empty()) else { continue };
        let takes = cycle.arguments.len();
        if call.arguments.len() <= takes {
            continue;
        }
        let range = call.arguments[takes..].iter().flatten().next().map_or(statement.range, |first| first.range);
        let message = format!(
            "{name} takes {takes} arguments in the classic cycles (`cycle-version`), and this call passes {}: cycle argument lists differ between versions of the control (004:3298-3302); SINUMERIK Operate adds arguments after these",
            call.arguments.len()
        );
        out.push(Diagnostic::new(&CYCLE_ARGUMENTS_FOR_VERSION, range, message));
    }
}

/// Rule 4.
fn length(text: &str, out: &mut Vec<Diagnostic>) {
    let line = text.trim_end_matches(['\n', '\r']);
    let Some((start, _)) = line.char_indices().nth(MAX_BLOCK_CHARS) else { return };
    let chars = line.chars().count();
    let range = TextRange::new(TextSize::from(start as u32), TextSize::of(line));
    let message = format!("the block has {chars} characters: the control reads at most {MAX_BLOCK_CHARS}");
    out.push(Diagnostic::new(&BLOCK_TOO_LONG, range, message));
}

/// Rule 7: the codes of the block by their modal group, G and M codes
/// written with their number and the words that stand in a group.
fn groups(catalogue: &Catalogue, block: &SinumerikBlock, out: &mut Vec<Diagnostic>) {
    let mut seen: Vec<(usize, String, TextRange)> = Vec::new();
    for statement in &block.statements {
        let code = match &statement.kind {
            StatementKind::Word(word) => {
                let &[letter] = word.address.as_bytes() else { continue };
                let Some(number) = word.value.as_ref().and_then(number).and_then(|n| n.whole()) else { continue };
                let Ok(number) = u32::try_from(number) else { continue };
                catalogue
                    .modal_group_index(char::from(letter), number)
                    .map(|group| (group, format!("{}{number}", char::from(letter)), word.range))
            }
            StatementKind::Command(command) => catalogue
                .word_modal_group_index(&command.name)
                .map(|group| (group, command.name.clone(), statement.range)),
            _ => None,
        };
        let Some((group, code, range)) = code else { continue };
        match seen.iter().find(|(g, other, _)| *g == group && *other != code) {
            Some((_, first, first_range)) => {
                let title = catalogue.groups[group].title.to_lowercase();
                let message = format!(
                    "{first} and {code} are both in group {} ({title}): a block may hold one code of each group",
                    catalogue.groups[group].id
                );
                out.push(Diagnostic::new(&SAME_GROUP_IN_BLOCK, range, message).with_related(
                    None,
                    *first_range,
                    first.clone(),
                ));
            }
            None => seen.push((group, code, range)),
        }
    }
}

/// Rule 49: every R parameter with a literal number, read or written.
fn r_parameters(block: &SinumerikBlock, config: &Config, out: &mut Vec<Diagnostic>) {
    // The count is machine data: without it, any index may be the control's.
    let Some(count) = config.sinumerik.r_parameters else { return };
    let mut check = |kind: PlaceKind, indices: &[Expr]| {
        let [Expr { kind: ExprKind::Number(number), range }] = indices else { return };
        if kind != PlaceKind::Parameter {
            return;
        }
        match number.whole() {
            Some(index) if index < u64::from(count) => {}
            _ => {
                let last = count.saturating_sub(1);
                let message = format!(
                    "R{} is no R parameter: the control has R0 to R{last} (`[sinumerik] r-parameters` sets how many)",
                    number.decimal
                );
                out.push(Diagnostic::new(&R_PARAMETER_OUT_OF_RANGE, *range, message));
            }
        }
    };
    all_exprs(&block.statements, &mut |expr| {
        if let ExprKind::Name(place) = &expr.kind {
            check(place.kind, &place.indices);
        }
    });
    for statement in &block.statements {
        written_places(statement, &mut |place, _| check(place.kind, &place.indices));
    }
}

/// Rules 50, 55, 56 and 57.
fn statements(catalogue: &Catalogue, block: &SinumerikBlock, out: &mut Vec<Diagnostic>) {
    let sync = block.statements.iter().position(|s| matches!(s.kind, StatementKind::SyncAction { .. }));
    if let Some(sync) = sync
        && let Some(other) = block.statements.iter().enumerate().find(|&(index, _)| index != sync)
    {
        let message = "a synchronous action takes its block alone: put these statements in a block of their own";
        out.push(Diagnostic::new(&SYNC_ACTION_SHARES_BLOCK, other.1.range, message).with_related(
            None,
            block.statements[sync].range,
            "the synchronous action",
        ));
    }
    for statement in &block.statements {
        match &statement.kind {
            StatementKind::Assign { target, value } if target.kind == PlaceKind::GroupCode => {
                group_number(catalogue, &target.indices, value, statement.range, out);
            }
            StatementKind::Command(command) if INTERPOLATING_SPLINES.contains(&command.name.as_str()) => {
                let message = format!(
                    "{} passes through every point it is given, so on digitised or noisy points it follows every error; BSPLINE approximates the points and gives a smoother path (004:3488-3491)",
                    command.name
                );
                out.push(Diagnostic::new(&INTERPOLATING_SPLINE, statement.range, message));
            }
            StatementKind::Call(call) if matches!(&call.callee, Callee::Cycle(name) if name == "CYCLE832") => {
                let message = format!(
                    "CYCLE832 runs only with its option on the control; without it, write what it switches on: {CYCLE832_EXPANSION}"
                );
                out.push(Diagnostic::new(&CYCLE832_OPTION, statement.range, message));
            }
            _ => {}
        }
    }
    all_exprs(&block.statements, &mut |expr| {
        if let ExprKind::String(text) = &expr.kind
            && let Some(at) = text.find('\0')
        {
            let message =
                format!("the string holds a NUL character after {at} bytes: the control ends the string there");
            out.push(Diagnostic::new(&NUL_IN_STRING, expr.range, message));
        }
    });
}

/// Rule 53: the tool's system variables read under tool management.
fn tool_variables(block: &SinumerikBlock, out: &mut Vec<Diagnostic>) {
    all_exprs(&block.statements, &mut |expr| {
        let ExprKind::Name(place) = &expr.kind else { return };
        let Some((name, instead)) = TOOL_VARIABLES.iter().find(|(name, _)| place.name == *name) else { return };
        let message = format!(
            "{name} does not give the tool on a machine with tool management: call {instead} instead (004:3274-3280)"
        );
        out.push(Diagnostic::new(&TOOL_VARIABLE_UNDER_MANAGEMENT, expr.range, message));
    });
}

/// Rule 50: `G[n]=1` where G1 is a code of group n and not its first,
/// which `G[n]=1` selects (group 1: G0).
fn group_number(catalogue: &Catalogue, indices: &[Expr], value: &Expr, range: TextRange, out: &mut Vec<Diagnostic>) {
    let ([Expr { kind: ExprKind::Number(group), .. }], ExprKind::Number(index)) = (indices, &value.kind) else {
        return;
    };
    let (Some(group), Some(1)) = (group.whole(), index.whole()) else { return };
    let id = format!("G{group}");
    let Some(selected) = catalogue.code_at(&id, 1) else { return };
    let Some(g1) = catalogue.code('G', 1).filter(|code| code.group.as_deref() == Some(id.as_str())) else { return };
    if g1.code == selected.code {
        return;
    }
    let instead = g1.index.map_or_else(String::new, |n| format!(" (that is G[{group}]={n})"));
    let message = format!("G[{group}]=1 selects {}, the group's first code, not {}{instead}", selected.code, g1.code);
    out.push(Diagnostic::new(&GROUP_NUMBER_NOT_CODE, range, message));
}

/// Rule 80: the spline degree and point weights, where written as numbers.
fn spline_words(block: &SinumerikBlock, out: &mut Vec<Diagnostic>) {
    for word in block.words() {
        let Some(number) = word.value.as_ref().and_then(number) else { continue };
        let value = number.value();
        let problem = match word.address.as_str() {
            "SD" if value != 2.0 && value != 3.0 => "the spline degree SD is 2 or 3",
            "PW" if !(0.0..=3.0).contains(&value) => "a point weight PW is 0 to 3",
            _ => continue,
        };
        let message = format!("{}={}: {problem}", word.address, number.decimal);
        out.push(Diagnostic::new(&SPLINE_PARAMETER_RANGE, word.range, message));
    }
}

/// Whether `op` compares.
fn compares(op: BinaryOp) -> bool {
    matches!(op, BinaryOp::Eq | BinaryOp::Ne | BinaryOp::Lt | BinaryOp::Le | BinaryOp::Gt | BinaryOp::Ge)
}

/// Whether `op` is a logical operator a comparison is meant to bind
/// tighter than.
fn logical(op: BinaryOp) -> bool {
    matches!(op, BinaryOp::And | BinaryOp::Or | BinaryOp::Xor)
}

/// `range` widened over the parentheses written around it.
fn widen(text: &str, range: TextRange) -> TextRange {
    let (mut start, mut end) = (usize::from(range.start()), usize::from(range.end()));
    loop {
        let before = text[..start].trim_end();
        let after = text[end..].trim_start();
        if !(before.ends_with('(') && after.starts_with(')')) {
            return TextRange::new(TextSize::of(&text[..start]), TextSize::of(&text[..end]));
        }
        start = before.len() - 1;
        end = text.len() - after.len() + 1;
    }
}

fn parenthesised(text: &str, expr: &Expr) -> bool {
    widen(text, expr.range) != expr.range
}

/// The comparison priority: every comparison in `expr` with an
/// unparenthesised logical or `<<` operand, once per chain of comparisons
/// and logical operators, with a fix that puts each comparison in
/// parentheses (not for `<<`, whose intent is not clear).
fn priority(text: &str, expr: &Expr, out: &mut Vec<Diagnostic>) {
    let mut roots = Vec::new();
    chain_roots(text, expr, false, &mut roots);
    for root in roots {
        let mut items = Vec::new();
        let mut problem = None;
        flatten(text, root, true, &mut items, &mut problem);
        let Some(operand) = problem else { continue };
        let mut diagnostic = Diagnostic::new(
            &COMPARISON_PRIORITY,
            root.range,
            format!(
                "Sinumerik compares after {}: this reads `{}` as one operand of the comparison; put the comparisons in parentheses",
                operator_name(operand),
                text.get(std::ops::Range::<usize>::from(widen(text, operand.range))).unwrap_or_default()
            ),
        );
        let edits = parenthesise_comparisons(text, &items);
        if !edits.is_empty() {
            diagnostic = diagnostic.with_fix("Put the comparisons in parentheses", edits);
        }
        out.push(diagnostic);
    }
}

fn operator_name(expr: &Expr) -> &'static str {
    match expr.kind {
        ExprKind::Binary(BinaryOp::And, ..) => "AND",
        ExprKind::Binary(BinaryOp::Or, ..) => "OR",
        ExprKind::Binary(BinaryOp::Xor, ..) => "XOR",
        _ => "`<<`",
    }
}

/// Whether `expr` is a comparison or logical operation, which a chain
/// joins.
fn in_chain(expr: &Expr) -> bool {
    matches!(expr.kind, ExprKind::Binary(op, ..) if compares(op) || logical(op))
}

/// The outermost comparisons and logical operations of `expr`, and those
/// nested in parentheses or other operations.
fn chain_roots<'a>(text: &str, expr: &'a Expr, inside: bool, roots: &mut Vec<&'a Expr>) {
    let chain = in_chain(expr);
    if chain && (!inside || parenthesised(text, expr)) {
        roots.push(expr);
    }
    match &expr.kind {
        ExprKind::Binary(_, lhs, rhs) => {
            chain_roots(text, lhs, chain, roots);
            chain_roots(text, rhs, chain, roots);
        }
        ExprKind::Unary(_, operand) => chain_roots(text, operand, false, roots),
        ExprKind::Call { arguments, .. } | ExprKind::List(arguments) => {
            arguments.iter().flatten().for_each(|a| chain_roots(text, a, false, roots));
        }
        ExprKind::Name(place) => place.indices.iter().for_each(|i| chain_roots(text, i, false, roots)),
        _ => {}
    }
}

/// An operand or operator of a chain, in text order.
enum Item<'a> {
    Operand(&'a Expr),
    Operator(BinaryOp),
}

/// The operands and operators of the chain at `expr`, and the first
/// operand of a comparison that is an unparenthesised logical operation or
/// `<<`.
fn flatten<'a>(text: &str, expr: &'a Expr, root: bool, items: &mut Vec<Item<'a>>, problem: &mut Option<&'a Expr>) {
    let ExprKind::Binary(op, lhs, rhs) = &expr.kind else {
        items.push(Item::Operand(expr));
        return;
    };
    if !in_chain(expr) || (!root && parenthesised(text, expr)) {
        items.push(Item::Operand(expr));
        return;
    }
    if compares(*op) && problem.is_none() {
        let misread = |operand: &Expr| {
            matches!(operand.kind, ExprKind::Binary(inner, ..) if logical(inner) || inner == BinaryOp::Concat)
                && !parenthesised(text, operand)
        };
        *problem = [lhs, rhs].into_iter().find(|operand| misread(operand)).map(|operand| &**operand);
    }
    flatten(text, lhs, false, items, problem);
    items.push(Item::Operator(*op));
    flatten(text, rhs, false, items, problem);
}

/// Parentheses around each run of operands joined by comparisons, where
/// logical operators join the runs; none when an operand is a `<<`.
fn parenthesise_comparisons(text: &str, items: &[Item<'_>]) -> Vec<TextEdit> {
    let concat = items
        .iter()
        .any(|item| matches!(item, Item::Operand(e) if matches!(e.kind, ExprKind::Binary(BinaryOp::Concat, ..))));
    if concat {
        return Vec::new();
    }
    let mut edits = Vec::new();
    for run in items.split(|item| matches!(item, Item::Operator(op) if logical(*op))) {
        let compared = run.iter().any(|item| matches!(item, Item::Operator(op) if compares(*op)));
        let (Some(Item::Operand(first)), Some(Item::Operand(last))) = (run.first(), run.last()) else { continue };
        if compared {
            edits.push(TextEdit::replace(TextRange::empty(widen(text, first.range).start()), "("));
            edits.push(TextEdit::replace(TextRange::empty(widen(text, last.range).end()), ")"));
        }
    }
    edits
}
