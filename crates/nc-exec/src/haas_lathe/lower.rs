//! Haas blocks lowered to plain data: the words, macro statements and
//! comments of one line, with ranges relative to the block's start.
//!
//! Lowering reads only the block's green node (no red tree), so an edit
//! re-lowers the blocks it touched and nothing else. The parser accepts any
//! text, so every shape it can build lowers: what is missing or malformed
//! becomes [`ExprKind::Malformed`] or a `None` value, never a panic.

use std::fmt;

use ncc_syntax::{Decimal, Sign, SyntaxKind, TextRange, TextSize};
use rowan::{GreenNodeData, GreenTokenData, NodeOrToken};

pub use crate::green::Skip;
use crate::green::{GreenRef, children, is_trivia, kind, token_of};

/// One block (one line).
#[derive(Debug, Default, Clone, PartialEq)]
pub struct HaasBlock {
    /// The `N` word that starts the block (after `/`), if any.
    pub number: Option<Number>,
    /// `/` or `/n` at the block's start.
    pub skip: Option<Skip>,
    /// `O1234 (TITLE)`: the program number and the comment after it.
    pub program: Option<ProgramStart>,
    /// The address words in order, the block number included; corner words
    /// are in [`HaasBlock::corners`].
    pub words: Vec<Word>,
    /// `,C1.` and `,R2.`.
    pub corners: Vec<Word>,
    /// Macro statements; the control allows one a block, the parser any
    /// number, so all are kept for a checker to see.
    pub statements: Vec<Statement>,
    pub comments: Vec<Comment>,
    /// The block's length in bytes, line break included.
    pub len: TextSize,
}

/// A block number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Number {
    /// `None` when not a whole number (`N1.5`) or missing.
    pub value: Option<u64>,
    pub range: TextRange,
}

/// The program number line's `O` word.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ProgramStart {
    /// `None` when missing or not a whole number.
    pub number: Option<u32>,
    /// The comment that follows on the line, without its parentheses.
    pub title: Option<String>,
    pub range: TextRange,
}

/// An address with its value.
#[derive(Debug, Clone, PartialEq)]
pub struct Word {
    /// The upper-case address letter.
    pub letter: u8,
    /// `None` when the value is missing or malformed (`X`, `U7.75.`).
    pub value: Option<Value>,
    pub range: TextRange,
    /// The value's range, sign included.
    pub value_range: Option<TextRange>,
}

/// A word's value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A number as written, with its sign.
    Literal(Decimal),
    /// `#n` or `#[expr]`, `index` being `n` or `expr`; `negative` for `X-#1`.
    Variable { negative: bool, index: Expr },
    /// `[expr]`; `negative` for `X-[#1+2.]`.
    Bracket { negative: bool, expr: Expr },
}

impl Value {
    /// The literal's value as a whole number, for addresses that name a
    /// block or program (`P10`, `Q20`, `P9010`).
    pub fn whole_number(&self) -> Option<u64> {
        match self {
            Value::Literal(decimal) => whole_number(decimal),
            _ => None,
        }
    }
}

impl Expr {
    /// The literal's value as a whole number (`GOTO 20`).
    pub fn whole_number(&self) -> Option<u64> {
        match &self.kind {
            ExprKind::Literal(decimal) => whole_number(decimal),
            _ => None,
        }
    }
}

fn whole_number(decimal: &Decimal) -> Option<u64> {
    decimal.scaled(0).and_then(|value| u64::try_from(value).ok())
}

/// A macro statement.
#[derive(Debug, Clone, PartialEq)]
pub enum Statement {
    /// `#target = value`; `target` is the variable's index expression.
    Assign { target: Expr, value: Expr, range: TextRange },
    /// `IF [condition] GOTO n` or `IF [condition] THEN #v = e`; `then` is
    /// `None` when the parser found neither.
    If { condition: Expr, then: Option<Box<Statement>>, range: TextRange },
    /// `GOTO n`.
    Goto { target: Expr, range: TextRange },
    /// `WHILE [condition] DOn` or `DOn` alone; `id` is `None` when the
    /// number is missing.
    LoopStart { condition: Option<Expr>, id: Option<u32>, range: TextRange },
    /// `ENDn`.
    LoopEnd { id: Option<u32>, range: TextRange },
}

/// A comment `( … )` or `; …`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Comment {
    pub range: TextRange,
    /// The text without `(`, `)` or `;`.
    pub body: String,
    /// A `(` comment that reaches the line's end without `)`.
    pub unclosed: bool,
}

/// An expression with its range.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub range: TextRange,
}

#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    Literal(Decimal),
    /// `#n`, `#[e]`: the variable whose number the expression gives.
    Variable(Box<Expr>),
    Unary(UnaryOp, Box<Expr>),
    Binary(BinaryOp, Box<Expr>, Box<Expr>),
    /// `SIN[e]`; `ATAN[y]/[x]` has two arguments.
    Call(Function, Vec<Expr>),
    /// What the parser reported as missing or wrong (`[#1 +`, `#`, `7.5.`).
    Malformed,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnaryOp {
    Plus,
    Minus,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    Mod,
    And,
    Or,
    Xor,
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
}

/// Each operator with its symbol, both ways.
const OPERATORS: [(BinaryOp, &str); 14] = [
    (BinaryOp::Add, "+"),
    (BinaryOp::Sub, "-"),
    (BinaryOp::Mul, "*"),
    (BinaryOp::Div, "/"),
    (BinaryOp::Mod, "MOD"),
    (BinaryOp::And, "AND"),
    (BinaryOp::Or, "OR"),
    (BinaryOp::Xor, "XOR"),
    (BinaryOp::Eq, "EQ"),
    (BinaryOp::Ne, "NE"),
    (BinaryOp::Gt, "GT"),
    (BinaryOp::Ge, "GE"),
    (BinaryOp::Lt, "LT"),
    (BinaryOp::Le, "LE"),
];

impl BinaryOp {
    /// The operator written as `symbol` (`+`, `MOD`, `EQ`).
    pub fn from_symbol(symbol: &str) -> Option<BinaryOp> {
        OPERATORS.iter().find(|&&(_, s)| s == symbol).map(|&(op, _)| op)
    }

    pub fn symbol(self) -> &'static str {
        OPERATORS.iter().find(|&&(op, _)| op == self).map_or("?", |&(_, s)| s)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Function {
    Sin,
    Cos,
    Tan,
    Atan,
    Asin,
    Acos,
    Sqrt,
    Abs,
    Round,
    Fix,
    Fup,
}

/// Each function with its name, both ways.
const FUNCTIONS: [(Function, &str); 11] = [
    (Function::Sin, "SIN"),
    (Function::Cos, "COS"),
    (Function::Tan, "TAN"),
    (Function::Atan, "ATAN"),
    (Function::Asin, "ASIN"),
    (Function::Acos, "ACOS"),
    (Function::Sqrt, "SQRT"),
    (Function::Abs, "ABS"),
    (Function::Round, "ROUND"),
    (Function::Fix, "FIX"),
    (Function::Fup, "FUP"),
];

impl Function {
    /// The function named `name` (`SIN`).
    pub fn from_name(name: &str) -> Option<Function> {
        FUNCTIONS.iter().find(|&&(_, n)| n == name).map(|&(function, _)| function)
    }

    pub fn name(self) -> &'static str {
        FUNCTIONS.iter().find(|&&(function, _)| function == self).map_or("?", |&(_, n)| n)
    }
}

impl HaasBlock {
    /// Lowers a `BLOCK` green node of the Haas parser.
    pub fn lower(block: &GreenNodeData) -> HaasBlock {
        let mut data = HaasBlock { len: block.text_len(), ..HaasBlock::default() };
        for (range, child) in children(block, TextSize::from(0)) {
            match child {
                NodeOrToken::Token(token) if kind(token.kind()) == SyntaxKind::COMMENT => {
                    let comment = lower_comment(token, range);
                    if let Some(program) = data.program.as_mut().filter(|p| p.title.is_none()) {
                        program.title = Some(comment.body.clone());
                    }
                    data.comments.push(comment);
                }
                NodeOrToken::Token(_) => {}
                NodeOrToken::Node(node) => match kind(node.kind()) {
                    SyntaxKind::WORD => {
                        let (word, corner) = lower_word(node, range);
                        if corner {
                            data.corners.push(word);
                        } else {
                            let first = data.words.is_empty() && data.statements.is_empty();
                            if first && word.letter == b'N' {
                                let value = word.value.as_ref().and_then(Value::whole_number);
                                data.number = Some(Number { value, range: word.range });
                            }
                            data.words.push(word);
                        }
                    }
                    SyntaxKind::PROGRAM_NUMBER => {
                        let number = children(node, range.start())
                            .find_map(|(_, c)| token_of(c, SyntaxKind::NUMBER))
                            .and_then(|t| Decimal::parse(None, t.text()))
                            .and_then(|d| whole_number(&d))
                            .and_then(|v| u32::try_from(v).ok());
                        data.program = Some(ProgramStart { number, title: None, range });
                    }
                    SyntaxKind::BLOCK_SKIP => data.skip = Some(Skip::lower(node, range)),
                    _ => data.statements.extend(lower_statement(node, range)),
                },
            }
        }
        data
    }

    /// The words with `letter`.
    pub fn words_with(&self, letter: u8) -> impl Iterator<Item = &Word> {
        self.words.iter().filter(move |w| w.letter == letter)
    }

    /// The first word with `letter`.
    pub fn word(&self, letter: u8) -> Option<&Word> {
        self.words_with(letter).next()
    }

    /// The G or M codes written as unsigned whole literals (`G01` → 1).
    pub fn codes(&self, letter: u8) -> impl Iterator<Item = u32> + '_ {
        self.code_words(letter).map(|(code, _)| code)
    }

    /// The G or M codes with their words.
    pub fn code_words(&self, letter: u8) -> impl Iterator<Item = (u32, &Word)> + '_ {
        self.words_with(letter).filter_map(|w| match &w.value {
            Some(Value::Literal(d)) if !d.has_point() && d.sign().is_none() => {
                d.scaled(0).and_then(|v| u32::try_from(v).ok()).map(|code| (code, w))
            }
            _ => None,
        })
    }

    pub fn has_code(&self, letter: u8, number: u32) -> bool {
        self.codes(letter).any(|code| code == number)
    }

    /// Whether the block holds anything the control executes.
    pub fn has_content(&self) -> bool {
        !self.words.is_empty() || !self.corners.is_empty() || !self.statements.is_empty() || self.program.is_some()
    }
}

/// The `BLOCK` nodes of a Haas `SOURCE_FILE` with their ranges in the file,
/// in order; tape marks are not blocks.
pub fn block_nodes(file: &GreenNodeData) -> impl Iterator<Item = (TextRange, &GreenNodeData)> {
    children(file, TextSize::from(0))
        .filter_map(|(range, child)| match child {
            NodeOrToken::Node(run) if kind(run.kind()) == SyntaxKind::BLOCK_RUN => Some(children(run, range.start())),
            _ => None,
        })
        .flatten()
        .filter_map(|(range, child)| match child {
            NodeOrToken::Node(block) if kind(block.kind()) == SyntaxKind::BLOCK => Some((range, block)),
            _ => None,
        })
}

fn lower_comment(token: &GreenTokenData, range: TextRange) -> Comment {
    let text = token.text();
    let (body, unclosed) = match text.strip_prefix('(') {
        Some(rest) => match rest.strip_suffix(')') {
            Some(body) => (body, false),
            None => (rest, true),
        },
        None => (text.strip_prefix(';').unwrap_or(text), false),
    };
    Comment { range, body: body.trim().to_owned(), unclosed }
}

/// A word and whether it is a corner word (`,C1.`).
fn lower_word(node: &GreenNodeData, range: TextRange) -> (Word, bool) {
    let mut corner = false;
    let mut letter = b'?';
    let mut sign = None;
    let mut value = None;
    let mut value_start = None;
    let mut literal_parts = 0;
    for (item_range, item) in children(node, range.start()) {
        let item_kind = kind(item.kind());
        if matches!(
            item_kind,
            SyntaxKind::PLUS | SyntaxKind::MINUS | SyntaxKind::NUMBER | SyntaxKind::VAR_REF | SyntaxKind::BRACKET_EXPR
        ) {
            value_start.get_or_insert(item_range.start());
        }
        match (item_kind, item) {
            (SyntaxKind::COMMA, _) => corner = true,
            (SyntaxKind::LETTER, NodeOrToken::Token(token)) => {
                letter = token.text().as_bytes()[0].to_ascii_uppercase();
            }
            (SyntaxKind::PLUS, _) => sign = Some(Sign::Plus),
            (SyntaxKind::MINUS, _) => sign = Some(Sign::Minus),
            (SyntaxKind::NUMBER, NodeOrToken::Token(token)) => {
                literal_parts += 1;
                // `U7.75.` is two number tokens: no value can be read.
                value = if literal_parts == 1 { Decimal::parse(sign, token.text()).map(Value::Literal) } else { None };
            }
            (SyntaxKind::VAR_REF, NodeOrToken::Node(var)) => {
                let index = lower_var_index(var, item_range);
                value = Some(Value::Variable { negative: sign == Some(Sign::Minus), index });
            }
            (SyntaxKind::BRACKET_EXPR, NodeOrToken::Node(bracket)) => {
                let expr = lower_bracket(bracket, item_range);
                value = Some(Value::Bracket { negative: sign == Some(Sign::Minus), expr });
            }
            _ => {}
        }
    }
    let value_range = value_start.map(|start| TextRange::new(start, range.end()));
    (Word { letter, value, range, value_range }, corner)
}

/// A statement node of a block; `None` for error nodes.
fn lower_statement(node: &GreenNodeData, range: TextRange) -> Option<Statement> {
    let mut items = children(node, range.start()).filter(|(_, c)| !is_trivia(*c));
    match kind(node.kind()) {
        SyntaxKind::ASSIGN => {
            let target = match items.next() {
                Some((var_range, NodeOrToken::Node(var))) => lower_var_index(var, var_range),
                _ => malformed(range),
            };
            let value = items.find_map(|(r, c)| expr_child(c, r)).unwrap_or_else(|| malformed(range));
            Some(Statement::Assign { target, value, range })
        }
        SyntaxKind::IF_STMT => {
            let mut condition = None;
            let mut then = None;
            for (item_range, item) in items {
                match (kind(item.kind()), item) {
                    (SyntaxKind::BRACKET_EXPR, NodeOrToken::Node(bracket)) => {
                        condition = Some(lower_bracket(bracket, item_range));
                    }
                    (SyntaxKind::GOTO_STMT | SyntaxKind::ASSIGN, NodeOrToken::Node(inner)) => {
                        then = lower_statement(inner, item_range).map(Box::new);
                    }
                    _ => {}
                }
            }
            Some(Statement::If { condition: condition.unwrap_or_else(|| malformed(range)), then, range })
        }
        SyntaxKind::GOTO_STMT => {
            let target = items.find_map(|(r, c)| expr_child(c, r)).unwrap_or_else(|| malformed(range));
            Some(Statement::Goto { target, range })
        }
        SyntaxKind::LOOP_START => {
            let mut condition = None;
            let mut id = None;
            for (item_range, item) in items {
                match (kind(item.kind()), item) {
                    (SyntaxKind::BRACKET_EXPR, NodeOrToken::Node(bracket)) => {
                        condition = Some(lower_bracket(bracket, item_range));
                    }
                    (SyntaxKind::NUMBER, NodeOrToken::Token(token)) => id = token.text().parse().ok(),
                    _ => {}
                }
            }
            Some(Statement::LoopStart { condition, id, range })
        }
        SyntaxKind::LOOP_END => {
            let id = items.find_map(|(_, c)| token_of(c, SyntaxKind::NUMBER)).and_then(|t| t.text().parse().ok());
            Some(Statement::LoopEnd { id, range })
        }
        _ => None,
    }
}

fn malformed(range: TextRange) -> Expr {
    Expr { kind: ExprKind::Malformed, range }
}

/// The expression a child is, if it is one.
fn expr_child(child: GreenRef<'_>, range: TextRange) -> Option<Expr> {
    match child {
        NodeOrToken::Node(node) => match kind(node.kind()) {
            SyntaxKind::LITERAL
            | SyntaxKind::VAR_REF
            | SyntaxKind::BRACKET_EXPR
            | SyntaxKind::PREFIX_EXPR
            | SyntaxKind::BIN_EXPR
            | SyntaxKind::CALL_EXPR => Some(lower_expr(node, range)),
            _ => None,
        },
        NodeOrToken::Token(_) => None,
    }
}

fn lower_expr(node: &GreenNodeData, range: TextRange) -> Expr {
    let items = || children(node, range.start()).filter(|(_, c)| !is_trivia(*c));
    let operands = || items().filter_map(|(r, c)| expr_child(c, r));
    let expr_kind = match kind(node.kind()) {
        SyntaxKind::LITERAL => literal(node, range),
        SyntaxKind::VAR_REF => ExprKind::Variable(Box::new(lower_var_index(node, range))),
        SyntaxKind::BRACKET_EXPR => return lower_bracket(node, range),
        SyntaxKind::PREFIX_EXPR => {
            let op = match items().next().map(|(_, c)| kind(c.kind())) {
                Some(SyntaxKind::MINUS) => UnaryOp::Minus,
                _ => UnaryOp::Plus,
            };
            match operands().next() {
                Some(operand) => ExprKind::Unary(op, Box::new(operand)),
                None => ExprKind::Malformed,
            }
        }
        SyntaxKind::BIN_EXPR => {
            let op = items().find_map(|(_, c)| match c {
                NodeOrToken::Token(token) => BinaryOp::from_symbol(token.text()),
                NodeOrToken::Node(_) => None,
            });
            let mut operands = operands();
            match (op, operands.next(), operands.next()) {
                (Some(op), Some(lhs), Some(rhs)) => ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                _ => ExprKind::Malformed,
            }
        }
        SyntaxKind::CALL_EXPR => {
            let name = items().find_map(|(_, c)| token_of(c, SyntaxKind::IDENT)).map(GreenTokenData::text);
            match name.and_then(Function::from_name) {
                Some(function) => ExprKind::Call(function, operands().collect()),
                None => ExprKind::Malformed,
            }
        }
        _ => ExprKind::Malformed,
    };
    Expr { kind: expr_kind, range }
}

/// A `LITERAL`: one number token; two mean a doubled decimal point.
fn literal(node: &GreenNodeData, range: TextRange) -> ExprKind {
    let mut numbers = children(node, range.start()).filter_map(|(_, c)| token_of(c, SyntaxKind::NUMBER));
    match (numbers.next(), numbers.next()) {
        (Some(number), None) => Decimal::parse(None, number.text()).map_or(ExprKind::Malformed, ExprKind::Literal),
        _ => ExprKind::Malformed,
    }
}

/// The inside of `[ … ]`; an empty bracket is malformed.
fn lower_bracket(node: &GreenNodeData, range: TextRange) -> Expr {
    children(node, range.start()).find_map(|(r, c)| expr_child(c, r)).unwrap_or_else(|| malformed(range))
}

/// The index expression of a `VAR_REF` (`#12` → 12, `#[#1+2]` → `#1+2`).
fn lower_var_index(node: &GreenNodeData, range: TextRange) -> Expr {
    for (item_range, item) in children(node, range.start()) {
        match (kind(item.kind()), item) {
            (SyntaxKind::NUMBER, NodeOrToken::Token(token)) => {
                let index = Decimal::parse(None, token.text()).map_or(ExprKind::Malformed, ExprKind::Literal);
                return Expr { kind: index, range: item_range };
            }
            (SyntaxKind::BRACKET_EXPR, NodeOrToken::Node(bracket)) => return lower_bracket(bracket, item_range),
            _ => {}
        }
    }
    malformed(range)
}

/// The block as the executor reads it, on one line (what `ncc lower`
/// prints): the block number, `/` when the block may be skipped, the
/// program number, the words in order with their values (`?` for a
/// missing one), the corner words, then the macro statements. Comments
/// and layout are not part of it; expressions are bracketed as grouped.
impl fmt::Display for HaasBlock {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut items: Vec<String> = Vec::new();
        let mut words = self.words.iter().peekable();
        if self.number.is_some() {
            items.extend(words.next().map(Word::to_string));
        }
        if let Some(skip) = self.skip {
            items.push(skip.level.map_or_else(|| "/".to_owned(), |level| format!("/{level}")));
        }
        if let Some(program) = &self.program {
            items.push(program.number.map_or_else(|| "O?".to_owned(), |number| format!("O{number}")));
        }
        items.extend(words.map(Word::to_string));
        items.extend(self.corners.iter().map(|corner| format!(",{corner}")));
        items.extend(self.statements.iter().map(Statement::to_string));
        f.write_str(&items.join(" "))
    }
}

impl fmt::Display for Word {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", char::from(self.letter))?;
        match &self.value {
            None => f.write_str("?"),
            Some(Value::Literal(decimal)) => write!(f, "{decimal}"),
            Some(Value::Variable { negative, index }) => write!(f, "{}#{}", sign(*negative), Index(index)),
            Some(Value::Bracket { negative, expr }) => write!(f, "{}[{expr}]", sign(*negative)),
        }
    }
}

fn sign(negative: bool) -> &'static str {
    if negative { "-" } else { "" }
}

impl fmt::Display for Statement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let id = |id: &Option<u32>| id.map_or_else(|| "?".to_owned(), |id| id.to_string());
        match self {
            Statement::Assign { target, value, .. } => write!(f, "#{}={value}", Index(target)),
            Statement::If { condition, then: Some(then), .. } => write!(f, "IF [{condition}] {then}"),
            Statement::If { condition, then: None, .. } => write!(f, "IF [{condition}] ?"),
            Statement::Goto { target, .. } => write!(f, "GOTO {target}"),
            Statement::LoopStart { condition: Some(condition), id: loop_id, .. } => {
                write!(f, "WHILE [{condition}] DO{}", id(loop_id))
            }
            Statement::LoopStart { condition: None, id: loop_id, .. } => write!(f, "DO{}", id(loop_id)),
            Statement::LoopEnd { id: loop_id, .. } => write!(f, "END{}", id(loop_id)),
        }
    }
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.kind {
            ExprKind::Literal(decimal) => write!(f, "{decimal}"),
            ExprKind::Variable(index) => write!(f, "#{}", Index(index)),
            ExprKind::Unary(op, operand) => {
                write!(f, "{}{}", if *op == UnaryOp::Minus { "-" } else { "+" }, Operand(operand))
            }
            ExprKind::Binary(op, left, right) => write!(f, "{} {} {}", Operand(left), op.symbol(), Operand(right)),
            ExprKind::Call(function, arguments) => {
                write!(f, "{}", function.name())?;
                arguments
                    .iter()
                    .enumerate()
                    .try_for_each(|(i, argument)| write!(f, "{}[{argument}]", if i > 0 { "/" } else { "" }))
            }
            ExprKind::Malformed => f.write_str("?"),
        }
    }
}

/// A variable's number: bracketed unless a literal (`#100`, `#[#1]`).
struct Index<'a>(&'a Expr);

impl fmt::Display for Index<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0.kind {
            ExprKind::Literal(_) => write!(f, "{}", self.0),
            _ => write!(f, "[{}]", self.0),
        }
    }
}

/// An operand: bracketed when it is itself an operation.
struct Operand<'a>(&'a Expr);

impl fmt::Display for Operand<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0.kind {
            ExprKind::Binary(..) | ExprKind::Unary(..) => write!(f, "[{}]", self.0),
            _ => write!(f, "{}", self.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use expect_test::expect;
    use ncc_syntax::{Dialect, Parse};
    use proptest::prelude::*;

    use super::*;

    fn lower_text(text: &str) -> Vec<HaasBlock> {
        let parse = Parse::new(text, Dialect::HaasLathe);
        let tree = parse.green();
        block_nodes(tree).map(|(_, block)| HaasBlock::lower(block)).collect()
    }

    /// A compact rendering of an expression, brackets around every operation.
    fn show(expr: &Expr) -> String {
        match &expr.kind {
            ExprKind::Literal(decimal) => decimal.to_string(),
            ExprKind::Variable(index) => format!("#{}", show(index)),
            ExprKind::Unary(UnaryOp::Minus, operand) => format!("-{}", show(operand)),
            ExprKind::Unary(UnaryOp::Plus, operand) => format!("+{}", show(operand)),
            ExprKind::Binary(op, lhs, rhs) => format!("[{} {op:?} {}]", show(lhs), show(rhs)),
            ExprKind::Call(function, arguments) => {
                let arguments: Vec<String> = arguments.iter().map(show).collect();
                format!("{function:?}({})", arguments.join(", "))
            }
            ExprKind::Malformed => "?".to_owned(),
        }
    }

    fn show_statement(statement: &Statement) -> String {
        match statement {
            Statement::Assign { target, value, .. } => format!("#{} = {}", show(target), show(value)),
            Statement::If { condition, then, .. } => {
                let then = then.as_deref().map_or("?".to_owned(), show_statement);
                format!("if {} then {then}", show(condition))
            }
            Statement::Goto { target, .. } => format!("goto {}", show(target)),
            Statement::LoopStart { condition, id, .. } => {
                format!("do{id:?} while {}", condition.as_ref().map_or("-".to_owned(), show))
            }
            Statement::LoopEnd { id, .. } => format!("end{id:?}"),
        }
    }

    fn show_block(block: &HaasBlock) -> String {
        let mut items = Vec::new();
        if let Some(program) = &block.program {
            items.push(format!("O{:?} {:?}", program.number, program.title));
        }
        if let Some(skip) = block.skip {
            items.push(format!("/{:?}", skip.level));
        }
        if let Some(number) = block.number {
            items.push(format!("N{:?}", number.value));
        }
        for word in block.words.iter().skip(usize::from(block.number.is_some())).chain(&block.corners) {
            let value = match &word.value {
                None => "?".to_owned(),
                Some(Value::Literal(decimal)) => decimal.to_string(),
                Some(Value::Variable { negative, index }) => {
                    format!("{}#{}", if *negative { "-" } else { "" }, show(index))
                }
                Some(Value::Bracket { negative, expr }) => {
                    format!("{}{}", if *negative { "-" } else { "" }, show(expr))
                }
            };
            items.push(format!("{}{value}", char::from(word.letter)));
        }
        items.extend(block.statements.iter().map(show_statement));
        items.extend(block.comments.iter().map(|c| format!("({})", c.body)));
        items.join(" ")
    }

    #[test]
    fn macro_program_lowers_to_words_and_statements() {
        let text = include_str!("../../../syntax/test_data/haas-lathe/macro_program.nc");
        let lowered: Vec<String> = lower_text(text).iter().map(show_block).collect();
        expect![[r##"
            [
                "OSome(9010) Some(\"BOLT CIRCLE\") (BOLT CIRCLE)",
                "#1 = 0 (counter)",
                "#2 = [#5 Mul 2.]",
                "#[#2 Add 100] = -#5",
                "#3 = [[[Sin(30.) Mul Cos(#1)] Add Atan(#1, 2.)] Sub Sqrt(Abs(#2))]",
                "#4 = [[[Round(#3) Mod 3] Add Fix([#2 Div 4])] Sub Fup(.5)]",
                "if [#1 Eq 0] then goto 20",
                "if [[#1 Gt 1] And [#2 Le 10.]] then #6 = [#1 Xor 1]",
                "doSome(1) while [#1 Lt 10]",
                "G01 X[#1 Mul 2.] Z-#2 F0.1",
                "#1 = [#1 Add 1]",
                "endSome(1)",
                "/Some(1) NSome(20) G65 P9010 A1. B2.",
                "NSome(30) goto #4",
                "doSome(2) while -",
                "endSome(2)",
                "M99",
            ]
        "##]]
        .assert_debug_eq(&lowered);
    }

    #[test]
    fn corner_words_signs_and_malformed_values() {
        let text = "G01 X30. ,C1. Z-20.,R2.\nU7.75. X Z+.5 W-[1] (OPEN\n#1 = [#2 +\nN1.5 IF [#1] THEN\n";
        let lowered: Vec<String> = lower_text(text).iter().map(show_block).collect();
        expect![[r##"
            [
                "G01 X30. Z-20. C1. R2.",
                "U? X? Z+.5 W-1 (OPEN)",
                "#1 = ?",
                "NNone if #1 then ?",
            ]
        "##]]
        .assert_debug_eq(&lowered);
        assert!(lower_text(text)[1].comments[0].unclosed);
    }

    #[test]
    fn ranges_are_relative_to_the_block() {
        let blocks = lower_text("G00 X1.\nN10 X-#2\n");
        let word = &blocks[1].words[1];
        assert_eq!(
            (word.range, word.value_range),
            (TextRange::new(4.into(), 8.into()), Some(TextRange::new(5.into(), 8.into())))
        );
        assert_eq!(blocks[1].len, TextSize::from(9));
    }

    proptest! {
        #[test]
        fn any_text_lowers(text in "[ -~\n]{0,120}") {
            lower_text(&text);
        }

        #[test]
        fn any_macro_soup_lowers(parts in prop::collection::vec(prop::sample::select(vec![
            "#", "[", "]", "=", "+", "-", "*", "/", " ", "\n", "1", "2.", ".", ",", "X", "N", "O", "(", ")", ";",
            "IF", "THEN", "GOTO", "WHILE", "DO", "END", "SIN", "ATAN", "MOD", "EQ", "AND", "%",
        ]), 0..60)) {
            lower_text(&parts.concat());
        }
    }
}
