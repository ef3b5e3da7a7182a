//! Macro expressions: a Pratt parser shared by the ISO dialects, whose
//! operator loop and number rules the Sinumerik parser shares too (its
//! values, names with indices and argument lists, are its own).
//!
//! The dialect supplies its tokens through [`ExprInput`] and its operators
//! through a [`Grammar`]: which tokens are binary operators with what
//! binding power, and which names are functions. The tree shapes are the
//! same for every dialect: `LITERAL`, `VAR_REF`, `BRACKET_EXPR`,
//! `CALL_EXPR`, `PREFIX_EXPR` and `BIN_EXPR`. Whitespace and comments
//! between the tokens of an expression belong to the innermost node that
//! spans them; an expression never reaches past the end of its line.

use std::ops::Range;

use rowan::NodeOrToken;

use crate::{
    SyntaxErrorKind as E,
    SyntaxKind::{self, *},
    green::{self, GreenElement},
};

/// The deepest nesting of brackets and signs an expression may have: deeper
/// input is reported instead of recursed into, so no line can exhaust the
/// stack.
pub(crate) const MAX_DEPTH: usize = 64;

/// A token found ahead: its kind and where it is.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ahead {
    pub(crate) kind: SyntaxKind,
    pub(crate) range: (usize, usize),
}

/// The dialect parser, as the expression parser sees it.
pub(crate) trait ExprInput<'t> {
    fn text(&self) -> &'t str;
    /// The position of the next token.
    fn pos(&self) -> usize;
    /// The next token at or after `from` that is not whitespace or a
    /// comment, if it is on the current line.
    fn significant_at(&self, from: usize) -> Option<Ahead>;
    /// The token at `pos` itself, trivia or not.
    fn token_kind_at(&self, pos: usize) -> Option<SyntaxKind>;
    /// Consumes the next token.
    fn bump(&mut self) -> GreenElement;
    /// Consumes the whitespace and comments before the next significant
    /// token into `into`.
    fn bump_trivia(&mut self, into: &mut Vec<GreenElement>);
    fn error(&mut self, kind: E, range: Range<usize>, message: String);
}

/// How a function takes its arguments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Arguments {
    /// `SIN[x]`.
    One,
    /// `ATAN[y]`, or `ATAN[y]/[x]`: a second bracket after `/` belongs to
    /// the call.
    OneOrSlashPair,
}

/// A dialect's operators.
pub(crate) struct Grammar {
    /// The left and right binding powers of a binary operator, given its
    /// token kind and text; higher binds tighter, and a left power below
    /// the right one makes the operator left-associative.
    pub(crate) binary: fn(SyntaxKind, &str) -> Option<(u8, u8)>,
    /// The argument form of a function name, `None` for other names.
    pub(crate) function: fn(&str) -> Option<Arguments>,
}

/// Parses an expression starting at the input's position, or reports a
/// missing one (`what` names what was expected) and returns `None`.
pub(crate) fn expr<'t>(input: &mut impl ExprInput<'t>, grammar: &Grammar, what: &str) -> Option<GreenElement> {
    expr_bp(input, grammar, 0, 0, what)
}

/// A value without binary operators: a number, a variable, a bracket, a
/// function call, or one of those after a sign.
pub(crate) fn atom<'t>(input: &mut impl ExprInput<'t>, grammar: &Grammar, what: &str) -> Option<GreenElement> {
    prefix(input, grammar, 0, what)
}

fn expr_bp<'t>(
    input: &mut impl ExprInput<'t>,
    grammar: &Grammar,
    min_bp: u8,
    depth: usize,
    what: &str,
) -> Option<GreenElement> {
    let lhs = prefix(input, grammar, depth, what)?;
    Some(binary_tail(input, grammar.binary, lhs, min_bp, |input, right, what| {
        expr_bp(input, grammar, right, depth, what)
    }))
}

/// The binary operations that follow `lhs` and bind at least `min_bp`:
/// the operator loop of the Pratt parser. `operand` parses a right-hand
/// side at the given binding power; a dialect with its own values (the
/// Sinumerik parser) shares the loop through it.
pub(crate) fn binary_tail<'t, I: ExprInput<'t>>(
    input: &mut I,
    binary: fn(SyntaxKind, &str) -> Option<(u8, u8)>,
    mut lhs: GreenElement,
    min_bp: u8,
    mut operand: impl FnMut(&mut I, u8, &str) -> Option<GreenElement>,
) -> GreenElement {
    while let Some(op) = input.significant_at(input.pos()) {
        let op_text = &input.text()[op.range.0..op.range.1];
        let Some((left, right)) = binary(op.kind, op_text) else { break };
        if left < min_bp {
            break;
        }
        let op_text = op_text.to_owned();
        let mut children = vec![lhs];
        input.bump_trivia(&mut children);
        children.push(input.bump());
        input.bump_trivia(&mut children);
        let what = format!("a value after `{op_text}`");
        if let Some(rhs) = operand(input, right, &what) {
            children.push(rhs);
        }
        lhs = NodeOrToken::Node(green::node(BIN_EXPR, children));
    }
    lhs
}

fn prefix<'t>(input: &mut impl ExprInput<'t>, grammar: &Grammar, depth: usize, what: &str) -> Option<GreenElement> {
    let pos = input.pos();
    let Some(next) = input.significant_at(pos).filter(|next| next.range.0 == pos) else {
        missing(input, what);
        return None;
    };
    if depth >= MAX_DEPTH && matches!(next.kind, PLUS | MINUS | L_BRACK | IDENT) {
        input.error(
            E::ExpectedExpression,
            next.range.0..next.range.1,
            format!("expression nested more than {MAX_DEPTH} deep"),
        );
        return None;
    }
    match next.kind {
        NUMBER => Some(literal(input)),
        HASH => Some(var_ref(input, grammar, depth)),
        L_BRACK => Some(bracket(input, grammar, depth)),
        PLUS | MINUS => {
            let mut children = vec![input.bump()];
            input.bump_trivia(&mut children);
            if let Some(operand) = prefix(input, grammar, depth + 1, "a value after the sign") {
                children.push(operand);
            }
            Some(NodeOrToken::Node(green::node(PREFIX_EXPR, children)))
        }
        IDENT => {
            let name = &input.text()[next.range.0..next.range.1];
            match (grammar.function)(name) {
                Some(arguments) => Some(call(input, grammar, depth, arguments)),
                None => {
                    missing(input, what);
                    None
                }
            }
        }
        _ => {
            missing(input, what);
            None
        }
    }
}

fn missing<'t>(input: &mut impl ExprInput<'t>, what: &str) {
    let pos = input.pos();
    let range = match input.significant_at(pos) {
        Some(next) if next.range.0 == pos && next.kind != NEWLINE => next.range.0..next.range.1,
        _ => pos..pos,
    };
    input.error(E::ExpectedExpression, range, format!("expected {what}"));
}

fn literal<'t>(input: &mut impl ExprInput<'t>) -> GreenElement {
    let mut children = Vec::new();
    number(input, &mut children);
    NodeOrToken::Node(green::node(LITERAL, children))
}

/// A number token into `children`, with a second one glued to it by a
/// doubled decimal point (`7.75.`), which is an error.
pub(crate) fn number<'t>(input: &mut impl ExprInput<'t>, children: &mut Vec<GreenElement>) {
    let start = input.pos();
    children.push(input.bump());
    let end = input.pos();
    if let Some(message) = placeholder(&input.text()[start..end]) {
        input.error(E::TemplatePlaceholder, start..end, message);
        return;
    }
    if input.text()[start..end].bytes().all(|b| b == b'.') {
        input.error(E::NumberWithoutDigits, start..end, "a number needs at least one digit (`0.` for zero)".into());
    }
    let glued = input.token_kind_at(end) == Some(NUMBER) && input.text().as_bytes()[end] == b'.';
    if glued && input.text().as_bytes()[start..end].contains(&b'.') {
        children.push(input.bump());
        let message = format!("a second decimal point in `{}`", &input.text()[start..input.pos()]);
        input.error(E::DoubledDecimalPoint, end..input.pos(), message);
    }
}

/// What is wrong with a number token that is a placeholder of a manual's
/// formats (`..`, `...`): points only.
pub(crate) fn placeholder(token: &str) -> Option<String> {
    (token.len() > 1 && token.bytes().all(|b| b == b'.'))
        .then(|| format!("`{token}` is a placeholder of the manual's formats, not a value: write the number"))
}

/// `#` and the variable number: `#100`, `#[#1+2]`.
pub(crate) fn var_ref<'t>(input: &mut impl ExprInput<'t>, grammar: &Grammar, depth: usize) -> GreenElement {
    let start = input.pos();
    let mut children = vec![input.bump()];
    match input.token_kind_at(input.pos()) {
        Some(NUMBER) => number(input, &mut children),
        Some(L_BRACK) => children.push(bracket(input, grammar, depth)),
        _ => input.error(
            E::ExpectedExpression,
            start..start + 1,
            "`#` must be followed by the variable number: `#100` or `#[#1+2]`".into(),
        ),
    }
    NodeOrToken::Node(green::node(VAR_REF, children))
}

/// `[`, an expression, `]`.
pub(crate) fn bracket<'t>(input: &mut impl ExprInput<'t>, grammar: &Grammar, depth: usize) -> GreenElement {
    let open = input.pos();
    let mut children = vec![input.bump()];
    input.bump_trivia(&mut children);
    if let Some(inner) = expr_bp(input, grammar, 0, depth + 1, "an expression inside the brackets") {
        children.push(inner);
    }
    match input.significant_at(input.pos()) {
        Some(Ahead { kind: R_BRACK, .. }) => {
            input.bump_trivia(&mut children);
            children.push(input.bump());
        }
        _ => input.error(E::UnclosedBracket, open..open + 1, "`[` is not closed by `]` on its line".into()),
    }
    NodeOrToken::Node(green::node(BRACKET_EXPR, children))
}

fn call<'t>(input: &mut impl ExprInput<'t>, grammar: &Grammar, depth: usize, arguments: Arguments) -> GreenElement {
    let name_start = input.pos();
    let mut children = vec![input.bump()];
    let name = input.text()[name_start..input.pos()].to_owned();
    match input.significant_at(input.pos()) {
        Some(Ahead { kind: L_BRACK, .. }) => {
            input.bump_trivia(&mut children);
            children.push(bracket(input, grammar, depth));
        }
        _ => {
            let message = format!("`{name}` takes its argument in brackets: `{name}[…]`");
            input.error(E::ExpectedExpression, name_start..name_start + name.len(), message);
        }
    }
    if arguments == Arguments::OneOrSlashPair {
        let slash = input.significant_at(input.pos()).filter(|next| next.kind == SLASH);
        let second = slash.and_then(|slash| input.significant_at(slash.range.1)).filter(|next| next.kind == L_BRACK);
        if second.is_some() {
            input.bump_trivia(&mut children);
            children.push(input.bump());
            input.bump_trivia(&mut children);
            children.push(bracket(input, grammar, depth));
        }
    }
    NodeOrToken::Node(green::node(CALL_EXPR, children))
}
