//! Sinumerik blocks lowered to plain data: the block number, label and
//! statements of one line, with ranges relative to the block's start.
//!
//! Lowering reads only the block's green node, so an edit re-lowers the
//! blocks it touched. The parser accepts any text, so every shape it builds
//! lowers: what is missing becomes [`ExprKind::Malformed`] or `None`, never
//! a panic; `ERROR` nodes, which the parser reported, are left out.
//!
//! The tree leaves to this step what only the catalogue knows
//! (the Sinumerik grammar of `ncc_syntax`): whether `NAME=…` writes a multi-letter
//! address (`CR=10`) or a variable, and whether a bare name is a command
//! (`TRAORI`, `BSPLINE`, `STOPRE`), a cycle (`CYCLE800`), a predefined
//! procedure (`MSG`, `WRITE`) or a program. A block-only code that takes
//! addresses (the frames `TRANS`, `ROT`, …, digest §2.2) takes the words of
//! those addresses that follow it in the block, and a call of a program
//! takes the repetition count `P` after it (digest §2.7).
//!
//! Assumptions (Siemens documentation, not in the seed): `'H1F'` and
//! `'B101'` are hexadecimal and binary constants; `REPEAT start [end] P=n`
//! repeats a program section; `M2` ends a main program like `M30`.

use ncc_catalog::{AddressRole, Catalogue, Dialect, KeywordKind, Modality};
use ncc_syntax::{Decimal, Sign, SyntaxKind, TextRange, TextSize};
use rowan::{GreenNodeData, GreenTokenData, NodeOrToken};

pub use crate::green::Skip;
use crate::green::{GreenRef, children, is_trivia, kind, token_of};

mod display;

/// One block (one line).
#[derive(Debug, Default, Clone, PartialEq)]
pub struct SinumerikBlock {
    /// `/` or `/n` at the block's start.
    pub skip: Option<Skip>,
    /// `%_N_PART_MPF`: the file's header line.
    pub header: Option<Header>,
    /// `N10`, or the main block `:10`.
    pub number: Option<BlockNumber>,
    /// `LABEL:` after the block number.
    pub label: Option<Label>,
    pub statements: Vec<Statement>,
    pub comments: Vec<Comment>,
    /// The block's length in bytes, line break included.
    pub len: TextSize,
    /// Whether a statement is one the program model reads (a structure, a
    /// declaration, a jump or a call): the model skips the others' lists,
    /// which a large file's words fill.
    pub modelled: bool,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    /// The name after `%`, as written (`_N_PART_MPF`).
    pub name: String,
    pub range: TextRange,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockNumber {
    /// `None` when not a whole number (`N1.5`).
    pub value: Option<u64>,
    /// Written `:10`: a main block.
    pub main: bool,
    pub range: TextRange,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Label {
    /// Upper case: names do not depend on case (004:1450).
    pub name: String,
    pub range: TextRange,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Comment {
    /// The text after `;`.
    pub body: String,
    pub range: TextRange,
}

/// A statement with its range.
#[derive(Debug, Clone, PartialEq)]
pub struct Statement {
    pub kind: StatementKind,
    pub range: TextRange,
}

// The statements are most of a lowered program's memory, and a CAM
// program's are words: the rare large statements keep their expressions
// boxed, so that a word does not take the room of a FOR.
const _: () = assert!(size_of::<Statement>() <= 88);

#[derive(Debug, Clone, PartialEq)]
pub enum StatementKind {
    /// An address with its value: `X10`, `X=R1`, `A3=1`, `CR=10`.
    Word(Word),
    /// `R1=5`, `R[R2]=0`, `VAC_POLE[0,1]=SET(…)`, `$TC_DP1[1,1]=120`, `G[8]=2`.
    Assign {
        target: Place,
        value: Box<Expr>,
    },
    /// A code or keyword of the catalogue written as a name (`TRAORI`,
    /// `BSPLINE`, `STOPRE`), with its arguments and, for a frame, its words.
    Command(Command),
    /// A call of a subprogram, cycle or predefined procedure.
    Call(Call),
    /// `MCALL name(…)`; `MCALL` alone (`None`) ends the modal call.
    ModalCall(Option<Call>),
    /// `RET`, with its arguments if any.
    Return {
        arguments: Vec<Option<Expr>>,
    },
    Def(Box<Def>),
    Proc(Proc),
    Extern(Extern),
    /// `DEFINE name AS text`.
    Define {
        name: String,
        text: String,
    },
    /// `IF cond`, or the one-line `IF cond GOTOF target` (no ENDIF).
    If {
        condition: Box<Expr>,
        jump: Option<Jump>,
    },
    Else,
    EndIf,
    While(Box<Expr>),
    EndWhile,
    /// `FOR var = start TO end`.
    For {
        variable: Place,
        start: Box<Expr>,
        end: Box<Expr>,
    },
    EndFor,
    Repeat,
    Until(Box<Expr>),
    Loop,
    EndLoop,
    /// `REPEAT start [end] P=n`: runs the section from label `start` to
    /// `end` (or the one block `start`) `n` times.
    RepeatSection {
        start: String,
        end: Option<String>,
        count: Option<Box<Expr>>,
    },
    /// `CASE value OF 1 GOTOF L1 … DEFAULT GOTOF L9`.
    Case {
        selector: Box<Expr>,
        arms: Vec<CaseArm>,
    },
    Jump(Jump),
    /// `[ID=n] [WHEN|WHENEVER|EVERY|FROM cond] DO actions`.
    SyncAction {
        id: Option<Box<SyncId>>,
        condition: Option<Box<Expr>>,
        actions: Vec<Statement>,
    },
}

/// The number of a synchronous action: `ID=1`, `IDS=2`.
#[derive(Debug, Clone, PartialEq)]
pub struct SyncId {
    /// `ID` or `IDS`.
    pub keyword: String,
    pub number: Expr,
}

/// An address with its value.
#[derive(Debug, Clone, PartialEq)]
pub struct Word {
    /// Upper case, with its extension: `X`, `A3`, `X1`, `CR`.
    pub address: String,
    /// `None` when missing or malformed (`X`, `X1.2.`).
    pub value: Option<WordValue>,
    pub range: TextRange,
    /// The value's range, sign included.
    pub value_range: Option<TextRange>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum WordValue {
    /// A number written after the address: `X-12.5`, `G642`.
    Literal(Number),
    /// After `=`: `X=R1+5`, `T="DRILL"`; `X=AC(10)` and `X=IC(5)` name
    /// their dimension.
    Expr { expr: Box<Expr>, dimension: Option<Dimension> },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimension {
    /// `AC(…)`.
    Absolute,
    /// `IC(…)`.
    Incremental,
}

/// A number as written, with its sign, times ten to `exponent` (`1.5EX-3`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Number {
    pub decimal: Decimal,
    pub exponent: i32,
}

impl Number {
    /// `digits` (`12.5`, `1EX3`) with a sign written before them.
    fn parse(sign: Option<Sign>, digits: &str) -> Option<Number> {
        let split = digits.as_bytes().iter().position(|b| b.eq_ignore_ascii_case(&b'E'));
        let (mantissa, exponent) = match split {
            Some(at) => (&digits[..at], digits.get(at + 2..)?.parse().ok()?),
            None => (digits, 0),
        };
        Some(Number { decimal: Decimal::parse(sign, mantissa)?, exponent })
    }

    pub fn value(&self) -> f64 {
        self.decimal.to_f64() * 10f64.powi(self.exponent)
    }

    /// The number as a whole number, if it is one (`N10`, `L140`, `P3`).
    pub fn whole(&self) -> Option<u64> {
        let value = if self.exponent >= 0 {
            self.decimal.scaled(self.exponent.unsigned_abs())?
        } else {
            let divisor = 10i128.checked_pow(self.exponent.unsigned_abs())?;
            let value = self.decimal.scaled(0)?;
            if value % divisor != 0 {
                return None;
            }
            value / divisor
        };
        u64::try_from(value).ok()
    }
}

/// A command of the catalogue written as a name.
#[derive(Debug, Clone, PartialEq)]
pub struct Command {
    /// Upper case.
    pub name: String,
    pub arguments: Vec<Option<Expr>>,
    /// The words a frame takes: `TRANS X10 Y20`.
    pub words: Vec<Word>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Call {
    pub callee: Callee,
    /// In order; `None` for an omitted one (`PROFIL(,TRUE)`, 004:1490-1517).
    pub arguments: Vec<Option<Expr>>,
    /// `PROFIL P3`: how many times the program runs.
    pub repetitions: Option<Box<WordValue>>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Callee {
    /// A name the catalogue does not know: a program, by its name in upper
    /// case (`PROFIL`, `_N_GEOMETRIE_VACKA_SPF`).
    Program(String),
    /// A cycle of the control (`CYCLE800`).
    Cycle(String),
    /// A predefined procedure or function (`MSG`, `WRITE`, `GROUP_BEGIN`).
    Predefined(String),
    /// A numbered subprogram `L140`, or an M function a subprogram
    /// replaces, `M6(T1)`.
    Numbered { letter: u8, number: Option<u64> },
    /// `PCALL /_N_SPF_DIR/_N_SUB_SPF`: the path as written.
    Path(String),
    /// `CALL program [BLOCK start TO end]`.
    Indirect { program: Box<Expr>, section: Option<Box<(Expr, Option<Expr>)>> },
}

impl Callee {
    /// The program's name when the call names one.
    pub fn program_name(&self) -> Option<&str> {
        match self {
            Callee::Program(name) | Callee::Cycle(name) | Callee::Path(name) => Some(name),
            Callee::Predefined(_) | Callee::Numbered { .. } | Callee::Indirect { .. } => None,
        }
    }

    /// The files the control looks the called program up in, in its
    /// order; `None` for a cycle, a predefined procedure, and a program
    /// only the run can name (`CALL` of an expression, `K12`).
    pub fn control_files(&self) -> Option<Vec<String>> {
        match self {
            Callee::Program(name) | Callee::Path(name) => Some(control_files(name)),
            Callee::Numbered { letter: b'L', number: Some(number) } => Some(control_files(&format!("L{number}"))),
            _ => None,
        }
    }
}

/// Whether `address` names an axis the control moves: its letter, or the
/// letter with a number (`A2`, `X1`).
pub fn is_axis(address: &str) -> bool {
    let Some((&letter, number)) = address.as_bytes().split_first() else { return false };
    b"XYZABCUVW".contains(&letter) && number.iter().all(u8::is_ascii_digit)
}

/// The files the control looks a program named `name` up in, in its
/// order: `PROFIL` is `_N_PROFIL_MPF`, found first, else `_N_PROFIL_SPF`
/// (004:1452-1462); `_N_PROFIL_SPF`, or a path ending in it, is that
/// file alone.
pub fn control_files(name: &str) -> Vec<String> {
    let name = name.rsplit('/').next().unwrap_or(name).trim().to_ascii_uppercase();
    if let Some(inner) = name.strip_prefix("_N_")
        && (inner.ends_with("_MPF") || inner.ends_with("_SPF"))
    {
        return vec![name];
    }
    ["MPF", "SPF"].iter().map(|kind| format!("_N_{name}_{kind}")).collect()
}

/// `DEF [scope] type name[dims]=value, …`.
#[derive(Debug, Clone, PartialEq)]
pub struct Def {
    /// `NCK` or `CHAN`, upper case.
    pub scope: Option<String>,
    pub ty: Type,
    pub names: Vec<Declared>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Type {
    pub base: BaseType,
    /// `STRING[50]`: the length.
    pub length: Option<Expr>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BaseType {
    Int,
    Real,
    Bool,
    Char,
    String,
    Axis,
    Frame,
    /// Missing: the parser reported it.
    Unknown,
}

impl BaseType {
    fn from_name(name: &str) -> BaseType {
        match name.to_ascii_uppercase().as_str() {
            "INT" => BaseType::Int,
            "REAL" => BaseType::Real,
            "BOOL" => BaseType::Bool,
            "CHAR" => BaseType::Char,
            "STRING" => BaseType::String,
            "AXIS" => BaseType::Axis,
            "FRAME" => BaseType::Frame,
            _ => BaseType::Unknown,
        }
    }
}

/// A name a DEF declares.
#[derive(Debug, Clone, PartialEq)]
pub struct Declared {
    /// Upper case.
    pub name: String,
    /// The array dimensions, empty for a single value.
    pub dimensions: Vec<Expr>,
    pub initial: Option<Expr>,
    pub range: TextRange,
}

/// `PROC name(parameters) attributes`.
#[derive(Debug, Clone, PartialEq)]
pub struct Proc {
    pub name: String,
    pub parameters: Vec<Parameter>,
    /// `SAVE`, `DISPLOF`, … in upper case.
    pub attributes: Vec<String>,
}

/// `EXTERN name(types)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Extern {
    pub name: String,
    pub parameters: Vec<Parameter>,
}

/// A formal parameter: `REAL X`, `VAR INT N`, `VAR REAL T[3,4]`, or a type
/// alone in EXTERN.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// `VAR`: passed by reference.
    pub by_reference: bool,
    pub ty: Type,
    pub name: Option<String>,
    pub dimensions: Vec<Expr>,
    pub range: TextRange,
}

#[derive(Debug, Clone, PartialEq)]
pub struct CaseArm {
    /// `None` for `DEFAULT`.
    pub value: Option<Expr>,
    pub jump: Jump,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Jump {
    pub kind: JumpKind,
    /// `None` for `GOTOS` and a missing target.
    pub target: Option<JumpTarget>,
    pub range: TextRange,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JumpKind {
    Goto,
    GotoF,
    GotoB,
    GotoC,
    /// Back to the program's start.
    GotoS,
}

#[derive(Debug, Clone, PartialEq)]
pub enum JumpTarget {
    /// `N10`; `None` when not a whole number.
    BlockNumber(Option<u64>),
    /// A label, upper case.
    Label(String),
    /// A string expression: `"N"<<R3`.
    Computed(Box<Expr>),
}

/// A variable, parameter or system variable, read or written.
#[derive(Debug, Clone, PartialEq)]
pub struct Place {
    pub kind: PlaceKind,
    /// Upper case: `R`, `VAC_POLE`, `$P_GG`, `G`, `X`.
    pub name: String,
    /// `R5` has the index 5; `VAC_POLE[1,0]` two.
    pub indices: Vec<Expr>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlaceKind {
    /// An R parameter.
    Parameter,
    /// A user variable, formal parameter or axis name.
    User,
    /// A name with `$`.
    System,
    /// `G[n]`: the code in force of G group n (004:3335-3341).
    GroupCode,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub range: TextRange,
}

#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    Number(Number),
    /// The text between the quotes.
    String(String),
    Bool(bool),
    /// `'H1F'`, `'B101'`.
    Integer(i64),
    /// A variable, or a name only its use explains (a label, an axis).
    Name(Place),
    /// `SIN(x)`, `ISFILE("…")`, `SET(1,2)`; name upper case, `None` for an
    /// omitted argument.
    Call {
        name: String,
        arguments: Vec<Option<Expr>>,
    },
    Unary(UnaryOp, Box<Expr>),
    Binary(BinaryOp, Box<Expr>, Box<Expr>),
    /// `(1,2,3)`: an array's values.
    List(Vec<Option<Expr>>),
    /// What the parser reported as missing or wrong.
    Malformed,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnaryOp {
    Plus,
    Minus,
    Not,
    BitNot,
    /// A leading `<<`: converts to a string.
    ToString,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    /// `DIV`: integer division.
    IntDiv,
    Mod,
    BitAnd,
    BitXor,
    BitOr,
    And,
    Xor,
    Or,
    /// `<<`.
    Concat,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    /// `:` chains frames.
    Chain,
}

/// How a block ends the program it is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgramEnd {
    /// `RET`: back to the caller, continuous-path mode kept (004:1561-1563).
    Return,
    /// `M17`: back to the caller.
    Subprogram,
    /// `M2`, `M30`.
    Program,
}

/// The M codes that end a program (004:1561-1563, 4103).
const END_CODES: [(u64, ProgramEnd); 3] =
    [(2, ProgramEnd::Program), (17, ProgramEnd::Subprogram), (30, ProgramEnd::Program)];

impl StatementKind {
    /// Whether the statement opens, continues or closes a control
    /// structure; a one-line `IF … GOTOF` does not.
    /// Whether the program model reads it: a structure, a declaration, a
    /// jump or a call.
    pub fn is_modelled(&self) -> bool {
        self.is_structure()
            || matches!(
                self,
                StatementKind::If { .. }
                    | StatementKind::Proc(_)
                    | StatementKind::Extern(_)
                    | StatementKind::Def(_)
                    | StatementKind::Jump(_)
                    | StatementKind::Case { .. }
                    | StatementKind::Call(_)
                    | StatementKind::ModalCall(_)
            )
    }

    pub fn is_structure(&self) -> bool {
        matches!(
            self,
            StatementKind::If { jump: None, .. }
                | StatementKind::Else
                | StatementKind::EndIf
                | StatementKind::While(_)
                | StatementKind::EndWhile
                | StatementKind::For { .. }
                | StatementKind::EndFor
                | StatementKind::Repeat
                | StatementKind::Until(_)
                | StatementKind::Loop
                | StatementKind::EndLoop
        )
    }
}

impl SinumerikBlock {
    /// Lowers a `BLOCK` green node of the Sinumerik parser.
    pub fn lower(block: &GreenNodeData) -> SinumerikBlock {
        let catalogue = Dialect::Sinumerik.catalogue();
        let mut data = SinumerikBlock { len: block.text_len(), ..SinumerikBlock::default() };
        let mut statements = Vec::new();
        for (range, child) in children(block, TextSize::from(0)) {
            match child {
                NodeOrToken::Token(token) if kind(token.kind()) == SyntaxKind::COMMENT => {
                    let body = token.text().strip_prefix(';').unwrap_or(token.text()).to_owned();
                    data.comments.push(Comment { body, range });
                }
                NodeOrToken::Token(_) => {}
                NodeOrToken::Node(node) => match kind(node.kind()) {
                    SyntaxKind::BLOCK_SKIP => data.skip = Some(Skip::lower(node, range)),
                    SyntaxKind::HEADER => {
                        let name = children(node, range.start())
                            .skip(1)
                            .filter_map(|(_, c)| c.into_token())
                            .map(GreenTokenData::text)
                            .collect();
                        data.header = Some(Header { name, range });
                    }
                    SyntaxKind::BLOCK_NUMBER if data.number.is_none() && statements.is_empty() => {
                        data.number = Some(block_number(node, range));
                    }
                    SyntaxKind::LABEL if data.label.is_none() && statements.is_empty() => {
                        let name = children(node, range.start())
                            .find_map(|(_, c)| token_of(c, SyntaxKind::IDENT))
                            .map_or_else(String::new, |t| t.text().to_ascii_uppercase());
                        data.label = Some(Label { name, range });
                    }
                    _ => statements.extend(lower_statement(catalogue, node, range)),
                },
            }
        }
        data.statements = attach_words(catalogue, statements);
        data.modelled = data.statements.iter().any(|statement| statement.kind.is_modelled());
        data
    }

    /// How this block ends its program, if it does: `RET`, `M17`, `M2`,
    /// `M30`.
    pub fn program_end(&self) -> Option<ProgramEnd> {
        self.statements.iter().find_map(|statement| match &statement.kind {
            StatementKind::Return { .. } => Some(ProgramEnd::Return),
            StatementKind::Word(word) if word.address == "M" => {
                let code = match &word.value {
                    Some(WordValue::Literal(number)) => number.whole(),
                    _ => None,
                }?;
                END_CODES.iter().find(|&&(number, _)| number == code).map(|&(_, end)| end)
            }
            _ => None,
        })
    }

    /// The words of the block, those a frame took included.
    pub fn words(&self) -> impl Iterator<Item = &Word> {
        self.statements.iter().flat_map(|statement| match &statement.kind {
            StatementKind::Word(word) => std::slice::from_ref(word),
            StatementKind::Command(command) => command.words.as_slice(),
            _ => &[],
        })
    }
}

/// The `BLOCK` nodes of a Sinumerik `SOURCE_FILE` with their ranges in the
/// file, in order.
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

/// The significant children of a node: no whitespace or comments.
fn items(node: &GreenNodeData, range: TextRange) -> impl Iterator<Item = (TextRange, GreenRef<'_>)> {
    children(node, range.start()).filter(|(_, c)| !is_trivia(*c))
}

/// The upper-case text of a token child.
fn upper(child: GreenRef<'_>) -> Option<String> {
    child.into_token().map(|token| token.text().to_ascii_uppercase())
}

fn block_number(node: &GreenNodeData, range: TextRange) -> BlockNumber {
    let mut numbers = items(node, range).filter_map(|(_, c)| token_of(c, SyntaxKind::NUMBER));
    let value = match (numbers.next(), numbers.next()) {
        (Some(number), None) => Number::parse(None, number.text()).and_then(|n| n.whole()),
        _ => None,
    };
    let main = items(node, range).next().is_some_and(|(_, c)| kind(c.kind()) == SyntaxKind::COLON);
    BlockNumber { value, main, range }
}

fn statement(kind: StatementKind, range: TextRange) -> Option<Statement> {
    Some(Statement { kind, range })
}

/// A statement node of a block; `None` for error nodes and misplaced
/// labels, which the parser reported.
fn lower_statement(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Option<Statement> {
    let keyword = || items(node, range).next().and_then(|(_, c)| upper(c)).unwrap_or_default();
    let exprs = || items(node, range).filter_map(|(r, c)| expr_child(catalogue, c, r));
    let first_expr = || exprs().next().unwrap_or_else(|| malformed(range));
    let kind = match kind(node.kind()) {
        SyntaxKind::WORD => return statement(lower_word(catalogue, node, range), range),
        SyntaxKind::ASSIGN => lower_assign(catalogue, node, range),
        SyntaxKind::CALL_STMT => lower_call_statement(catalogue, node, range)?,
        SyntaxKind::DEF_STMT => StatementKind::Def(Box::new(lower_def(catalogue, node, range))),
        SyntaxKind::PROC_STMT => {
            let (name, parameters, attributes) = lower_signature(catalogue, node, range);
            StatementKind::Proc(Proc { name, parameters, attributes })
        }
        SyntaxKind::EXTERN_STMT => {
            let (name, parameters, _) = lower_signature(catalogue, node, range);
            StatementKind::Extern(Extern { name, parameters })
        }
        SyntaxKind::MACRO_DEF => {
            let mut parts = items(node, range).skip(1);
            let name = parts.next().and_then(|(_, c)| upper(c)).unwrap_or_default();
            let text_start = parts.next().map_or(range.end(), |(r, _)| r.end());
            let text: String = children(node, range.start())
                .filter(|(r, _)| r.start() >= text_start)
                .filter_map(|(_, c)| c.into_token())
                .map(GreenTokenData::text)
                .collect();
            StatementKind::Define { name, text: text.trim().to_owned() }
        }
        SyntaxKind::IF_STMT => {
            let jump = items(node, range).find_map(|(r, c)| match c {
                NodeOrToken::Node(goto) if kind(goto.kind()) == SyntaxKind::GOTO_STMT => {
                    Some(lower_jump(catalogue, goto, r))
                }
                _ => None,
            });
            StatementKind::If { condition: Box::new(first_expr()), jump }
        }
        SyntaxKind::ELSE_STMT => StatementKind::Else,
        SyntaxKind::ENDIF_STMT => StatementKind::EndIf,
        SyntaxKind::LOOP_START => match keyword().as_str() {
            "WHILE" => StatementKind::While(Box::new(first_expr())),
            "LOOP" => StatementKind::Loop,
            "REPEAT" => StatementKind::Repeat,
            _ => lower_for(catalogue, node, range),
        },
        SyntaxKind::LOOP_END => match keyword().as_str() {
            "ENDWHILE" => StatementKind::EndWhile,
            "ENDFOR" => StatementKind::EndFor,
            "ENDLOOP" => StatementKind::EndLoop,
            _ => StatementKind::Until(Box::new(first_expr())),
        },
        SyntaxKind::CASE_STMT => {
            let arms = items(node, range)
                .filter_map(|(r, c)| match c {
                    NodeOrToken::Node(arm) if kind(arm.kind()) == SyntaxKind::CASE_ARM => {
                        lower_case_arm(catalogue, arm, r)
                    }
                    _ => None,
                })
                .collect();
            StatementKind::Case { selector: Box::new(first_expr()), arms }
        }
        SyntaxKind::GOTO_STMT => StatementKind::Jump(lower_jump(catalogue, node, range)),
        SyntaxKind::SYNC_ACTION => {
            let mut condition = None;
            let mut actions = Vec::new();
            let mut after_do = false;
            for (r, c) in items(node, range) {
                match c {
                    NodeOrToken::Token(token) if token.text().eq_ignore_ascii_case("DO") => after_do = true,
                    NodeOrToken::Node(child) if after_do => actions.extend(lower_statement(catalogue, child, r)),
                    _ if condition.is_none() => condition = expr_child(catalogue, c, r),
                    _ => {}
                }
            }
            StatementKind::SyncAction {
                id: None,
                condition: condition.map(Box::new),
                actions: attach_words(catalogue, actions),
            }
        }
        _ => return None,
    };
    statement(kind, range)
}

/// A `WORD` node: `X10`, `X-1.5`, `X=expr`, `A3=1`.
fn lower_word(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> StatementKind {
    let mut address = String::new();
    let mut sign = None;
    let mut value = None;
    let mut value_start = None;
    let mut numbers = 0;
    let mut after_eq = false;
    for (item_range, item) in children(node, range.start()) {
        match (kind(item.kind()), item) {
            (SyntaxKind::LETTER, NodeOrToken::Token(token)) => address = token.text().to_ascii_uppercase(),
            (SyntaxKind::EQ, _) => after_eq = true,
            // The extension before `=`: `A3=`.
            (SyntaxKind::NUMBER, NodeOrToken::Token(token)) if !after_eq && numbers == 0 => {
                if has_eq(node) && sign.is_none() {
                    address.push_str(token.text());
                } else {
                    value_start.get_or_insert(item_range.start());
                    value = Number::parse(sign, token.text()).map(WordValue::Literal);
                    numbers += 1;
                }
            }
            (SyntaxKind::NUMBER, _) if !after_eq => {
                // `X1.2.` is two number tokens: no value can be read.
                value = None;
                numbers += 1;
            }
            (SyntaxKind::PLUS | SyntaxKind::MINUS, _) if !after_eq => {
                value_start = Some(item_range.start());
                sign = Some(if kind(item.kind()) == SyntaxKind::MINUS { Sign::Minus } else { Sign::Plus });
            }
            _ if after_eq && value.is_none() => {
                if let Some(expr) = expr_child(catalogue, item, item_range) {
                    value_start = Some(item_range.start());
                    value = Some(word_expr(expr));
                }
            }
            _ => {}
        }
    }
    let value_range = value_start.map(|start| TextRange::new(start, range.end()));
    let word = Word { address, value, range, value_range };
    numbered_call(catalogue, &word).unwrap_or(StatementKind::Word(word))
}

fn has_eq(node: &GreenNodeData) -> bool {
    node.children().any(|c| kind(c.kind()) == SyntaxKind::EQ)
}

/// `L140` without arguments: the call of a numbered subprogram (the
/// address whose role is the label).
fn numbered_call(catalogue: &Catalogue, word: &Word) -> Option<StatementKind> {
    let &[letter] = word.address.as_bytes() else { return None };
    if catalogue.role_of(letter) != Some(AddressRole::Label) {
        return None;
    }
    let Some(WordValue::Literal(number)) = &word.value else { return None };
    let callee = Callee::Numbered { letter, number: number.whole() };
    Some(StatementKind::Call(Call { callee, arguments: Vec::new(), repetitions: None }))
}

/// The value of `address=expr`, with `AC(…)`/`IC(…)` unwrapped.
fn word_expr(expr: Expr) -> WordValue {
    if let ExprKind::Call { name, arguments } = &expr.kind
        && let [Some(inner)] = arguments.as_slice()
    {
        let dimension = match name.as_str() {
            "AC" => Some(Dimension::Absolute),
            "IC" => Some(Dimension::Incremental),
            _ => None,
        };
        if dimension.is_some() {
            return WordValue::Expr { expr: Box::new(inner.clone()), dimension };
        }
    }
    WordValue::Expr { expr: Box::new(expr), dimension: None }
}

/// `target=value`; a name the catalogue knows as an address of several
/// letters is a word (`CR=10`).
fn lower_assign(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> StatementKind {
    let mut parts = items(node, range).filter(|(_, c)| kind(c.kind()) != SyntaxKind::EQ);
    let target = parts.next().and_then(|(r, c)| c.into_node().map(|n| (r, n)));
    let value = parts.find_map(|(r, c)| expr_child(catalogue, c, r));
    if let Some((target_range, target)) = target
        && kind(target.kind()) == SyntaxKind::NAME_REF
    {
        let name = name_of(target, target_range);
        if name.len() > 1 && catalogue.address(&name).is_some() {
            let value_range = value.as_ref().map(|v| TextRange::new(v.range.start(), range.end()));
            let value = value.map(word_expr);
            return StatementKind::Word(Word { address: name, value, range, value_range });
        }
    }
    let target = match target {
        Some((r, n)) => place(catalogue, n, r),
        None => Place { kind: PlaceKind::User, name: String::new(), indices: Vec::new() },
    };
    StatementKind::Assign { target, value: Box::new(value.unwrap_or_else(|| malformed(range))) }
}

/// The name of a `NAME_REF`: its name, or its letter and digits (`X1`),
/// upper case.
fn name_of(node: &GreenNodeData, range: TextRange) -> String {
    items(node, range).filter_map(|(_, c)| upper(c)).collect()
}

/// `NAME_REF`, `INDEX_EXPR` or `PARAM_REF` as a place.
fn place(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Place {
    match kind(node.kind()) {
        SyntaxKind::PARAM_REF => {
            let indices = match items(node, range).nth(1) {
                Some((r, NodeOrToken::Token(number))) if kind(number.kind()) == SyntaxKind::NUMBER => {
                    vec![number_expr(number.text(), r)]
                }
                _ => index_exprs(catalogue, node, range),
            };
            Place { kind: PlaceKind::Parameter, name: "R".to_owned(), indices }
        }
        SyntaxKind::INDEX_EXPR => {
            let name = items(node, range).find_map(|(r, c)| c.into_node().map(|n| name_of(n, r))).unwrap_or_default();
            let group = name.len() == 1 && catalogue.preparatory_letter().is_some_and(|g| name.as_bytes()[0] == g);
            let indices = index_exprs(catalogue, node, range);
            let kind = if group { PlaceKind::GroupCode } else { place_kind(&name) };
            Place { kind, name, indices }
        }
        _ => {
            let name = name_of(node, range);
            Place { kind: place_kind(&name), name, indices: Vec::new() }
        }
    }
}

fn place_kind(name: &str) -> PlaceKind {
    if name.starts_with('$') { PlaceKind::System } else { PlaceKind::User }
}

/// The expressions directly inside a node's `[ … ]`.
fn index_exprs(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Vec<Expr> {
    let mut inside = false;
    let mut indices = Vec::new();
    for (r, c) in items(node, range) {
        match kind(c.kind()) {
            SyntaxKind::L_BRACK => inside = true,
            SyntaxKind::R_BRACK => inside = false,
            _ if inside => indices.extend(expr_child(catalogue, c, r)),
            _ => {}
        }
    }
    indices
}

fn lower_call_statement(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Option<StatementKind> {
    let mut parts = items(node, range);
    let (first_range, first) = parts.next()?;
    let first_token = first.into_token()?;
    if kind(first_token.kind()) == SyntaxKind::LETTER {
        // `L140(1)`, `M6(T1)`.
        let letter = first_token.text().as_bytes()[0].to_ascii_uppercase();
        let number = parts.next().and_then(|(_, c)| token_of(c, SyntaxKind::NUMBER));
        let number = number.and_then(|n| Number::parse(None, n.text())).and_then(|n| n.whole());
        let arguments = arguments_of(catalogue, node, range);
        return Some(StatementKind::Call(Call {
            callee: Callee::Numbered { letter, number },
            arguments,
            repetitions: None,
        }));
    }
    let name = first_token.text().to_ascii_uppercase();
    let kind = match name.as_str() {
        "MCALL" => StatementKind::ModalCall(parts.find_map(|(r, c)| match c {
            NodeOrToken::Node(inner) => match lower_call_statement(catalogue, inner, r) {
                Some(StatementKind::Call(call)) => Some(call),
                _ => None,
            },
            NodeOrToken::Token(_) => None,
        })),
        "CALL" => {
            let mut exprs = parts.filter_map(|(r, c)| expr_child(catalogue, c, r));
            let program = exprs.next().unwrap_or_else(|| malformed(first_range));
            let section = exprs.next().map(|start| (start, exprs.next()));
            let callee = Callee::Indirect { program: Box::new(program), section: section.map(Box::new) };
            StatementKind::Call(Call { callee, arguments: Vec::new(), repetitions: None })
        }
        "PCALL" => {
            let path = parts
                .filter_map(|(_, c)| c.into_token())
                .filter(|t| matches!(kind(t.kind()), SyntaxKind::SLASH | SyntaxKind::IDENT))
                .map(|t| t.text().to_ascii_uppercase())
                .collect();
            let arguments = arguments_of(catalogue, node, range);
            StatementKind::Call(Call { callee: Callee::Path(path), arguments, repetitions: None })
        }
        "RET" => StatementKind::Return { arguments: arguments_of(catalogue, node, range) },
        _ => {
            let arguments = arguments_of(catalogue, node, range);
            if catalogue.word_code(&name).is_some() || catalogue.keyword(&name).is_some() {
                StatementKind::Command(Command { name, arguments, words: Vec::new() })
            } else {
                let callee = if catalogue.cycles_for(&name).next().is_some() {
                    Callee::Cycle(name)
                } else if catalogue.function(&name).is_some() {
                    Callee::Predefined(name)
                } else {
                    Callee::Program(name)
                };
                StatementKind::Call(Call { callee, arguments, repetitions: None })
            }
        }
    };
    Some(kind)
}

/// The arguments of the node's `ARG_LIST`; none without one.
fn arguments_of(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Vec<Option<Expr>> {
    items(node, range)
        .find_map(|(r, c)| match c {
            NodeOrToken::Node(list) if kind(list.kind()) == SyntaxKind::ARG_LIST => {
                Some(list_values(catalogue, list, r))
            }
            _ => None,
        })
        .unwrap_or_default()
}

/// The values of `(a, , b)`, `None` for an empty position; `()` has none.
fn list_values(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Vec<Option<Expr>> {
    let mut values = Vec::new();
    let mut current = None;
    let mut commas = false;
    for (r, c) in items(node, range) {
        if kind(c.kind()) == SyntaxKind::COMMA {
            values.push(current.take());
            commas = true;
        } else if let Some(expr) = expr_child(catalogue, c, r) {
            current = Some(expr);
        }
    }
    if commas || current.is_some() {
        values.push(current);
    }
    values
}

fn lower_def(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Def {
    let mut scope = None;
    let mut ty = Type { base: BaseType::Unknown, length: None };
    let mut names = Vec::new();
    for (r, c) in items(node, range).skip(1) {
        match c {
            NodeOrToken::Token(token) if kind(token.kind()) == SyntaxKind::IDENT => {
                scope = Some(token.text().to_ascii_uppercase());
            }
            NodeOrToken::Node(child) if kind(child.kind()) == SyntaxKind::TYPE => ty = lower_type(catalogue, child, r),
            NodeOrToken::Node(child) if kind(child.kind()) == SyntaxKind::VAR_DECL => {
                let name = declared_name(child, r);
                let dimensions = index_exprs(catalogue, child, r);
                let mut after_eq = false;
                let mut initial = None;
                for (item_range, item) in items(child, r) {
                    if kind(item.kind()) == SyntaxKind::EQ {
                        after_eq = true;
                    } else if after_eq && initial.is_none() {
                        initial = expr_child(catalogue, item, item_range);
                    }
                }
                names.push(Declared { name, dimensions, initial, range: r });
            }
            _ => {}
        }
    }
    Def { scope, ty, names }
}

/// The name a node declares: an identifier, or a letter with its digits.
fn declared_name(node: &GreenNodeData, range: TextRange) -> String {
    items(node, range)
        .map_while(|(_, c)| match kind(c.kind()) {
            SyntaxKind::IDENT | SyntaxKind::LETTER | SyntaxKind::NUMBER => upper(c),
            _ => None,
        })
        .collect()
}

fn lower_type(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Type {
    let base = items(node, range)
        .next()
        .and_then(|(_, c)| c.into_token())
        .map_or(BaseType::Unknown, |t| BaseType::from_name(t.text()));
    Type { base, length: index_exprs(catalogue, node, range).into_iter().next() }
}

/// The name, parameters and attributes of `PROC` or `EXTERN`.
fn lower_signature(
    catalogue: &Catalogue,
    node: &GreenNodeData,
    range: TextRange,
) -> (String, Vec<Parameter>, Vec<String>) {
    let mut parts = items(node, range).skip(1).peekable();
    let mut name = String::new();
    if let Some((_, first)) = parts.next_if(|(_, c)| matches!(kind(c.kind()), SyntaxKind::IDENT | SyntaxKind::LETTER)) {
        name = upper(first).unwrap_or_default();
        // `L10`: a letter and its digits.
        if kind(first.kind()) == SyntaxKind::LETTER
            && let Some((_, digits)) = parts.next_if(|(_, c)| kind(c.kind()) == SyntaxKind::NUMBER)
        {
            name.extend(upper(digits));
        }
    }
    let mut parameters = Vec::new();
    let mut attributes = Vec::new();
    for (r, c) in parts {
        match (kind(c.kind()), c) {
            (SyntaxKind::PARAM, NodeOrToken::Node(param)) => parameters.push(lower_parameter(catalogue, param, r)),
            (SyntaxKind::IDENT, token) => attributes.extend(upper(token)),
            _ => {}
        }
    }
    (name, parameters, attributes)
}

fn lower_parameter(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Parameter {
    let mut by_reference = false;
    let mut ty = Type { base: BaseType::Unknown, length: None };
    let mut name: Option<String> = None;
    for (r, c) in items(node, range) {
        match (kind(c.kind()), c) {
            (SyntaxKind::TYPE, NodeOrToken::Node(type_node)) => ty = lower_type(catalogue, type_node, r),
            // `VAR`, the only name before the type.
            (SyntaxKind::IDENT, _) if ty.base == BaseType::Unknown => by_reference = true,
            (SyntaxKind::IDENT | SyntaxKind::LETTER | SyntaxKind::NUMBER, token) => {
                name.get_or_insert_with(String::new).extend(upper(token));
            }
            _ => {}
        }
    }
    let dimensions = index_exprs(catalogue, node, range);
    Parameter { by_reference, ty, name, dimensions, range }
}

/// `FOR var = start TO end`.
fn lower_for(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> StatementKind {
    let mut variable = Place { kind: PlaceKind::User, name: String::new(), indices: Vec::new() };
    let mut start = None;
    let mut end = None;
    for (r, c) in items(node, range).skip(1) {
        match c {
            NodeOrToken::Node(assign) if kind(assign.kind()) == SyntaxKind::ASSIGN => {
                if let StatementKind::Assign { target, value } = lower_assign(catalogue, assign, r) {
                    variable = target;
                    start = Some(value);
                }
            }
            // The variable without `= start`; a name after TO is the end.
            NodeOrToken::Node(target)
                if start.is_none() && matches!(kind(target.kind()), SyntaxKind::NAME_REF | SyntaxKind::PARAM_REF) =>
            {
                variable = place(catalogue, target, r);
            }
            _ => {
                if let Some(expr) = expr_child(catalogue, c, r) {
                    end = Some(expr);
                }
            }
        }
    }
    StatementKind::For {
        variable,
        start: start.unwrap_or_else(|| Box::new(malformed(range))),
        end: Box::new(end.unwrap_or_else(|| malformed(range))),
    }
}

fn lower_case_arm(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Option<CaseArm> {
    let mut value = None;
    let mut jump = None;
    for (r, c) in items(node, range) {
        match c {
            NodeOrToken::Node(goto) if kind(goto.kind()) == SyntaxKind::GOTO_STMT => {
                jump = Some(lower_jump(catalogue, goto, r));
            }
            _ => value = value.or_else(|| expr_child(catalogue, c, r)),
        }
    }
    Some(CaseArm { value, jump: jump? })
}

fn lower_jump(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Jump {
    let mut parts = items(node, range);
    let jump_kind = match parts.next().and_then(|(_, c)| upper(c)).as_deref() {
        Some("GOTOF") => JumpKind::GotoF,
        Some("GOTOB") => JumpKind::GotoB,
        Some("GOTOC") => JumpKind::GotoC,
        Some("GOTOS") => JumpKind::GotoS,
        _ => JumpKind::Goto,
    };
    let target = parts.next().and_then(|(r, c)| match c {
        NodeOrToken::Node(number) if kind(number.kind()) == SyntaxKind::BLOCK_NUMBER => {
            Some(JumpTarget::BlockNumber(block_number(number, r).value))
        }
        NodeOrToken::Node(name) if kind(name.kind()) == SyntaxKind::NAME_REF => {
            Some(JumpTarget::Label(name_of(name, r)))
        }
        _ => expr_child(catalogue, c, r).map(|expr| JumpTarget::Computed(Box::new(expr))),
    });
    Jump { kind: jump_kind, target, range }
}

/// What the parser leaves in a block after a statement: a frame takes the
/// words of the addresses it allows, a program call its repetition count,
/// `REPEAT` its labels and count, and a synchronous action the `ID=n`
/// before it.
fn attach_words(catalogue: &Catalogue, statements: Vec<Statement>) -> Vec<Statement> {
    let mut attached: Vec<Statement> = Vec::with_capacity(statements.len());
    for statement in statements {
        let Some(previous) = attached.last_mut() else {
            attached.push(statement);
            continue;
        };
        let taken = match (&mut previous.kind, &statement.kind) {
            (StatementKind::Command(command), StatementKind::Word(word)) if takes_word(catalogue, command, word) => {
                command.words.push(word.clone());
                true
            }
            (StatementKind::Call(call), StatementKind::Word(word))
                if call.repetitions.is_none()
                    && !matches!(call.callee, Callee::Predefined(_))
                    && is_count(catalogue, word) =>
            {
                call.repetitions = word.value.clone().map(Box::new);
                true
            }
            (StatementKind::Assign { target, value }, StatementKind::SyncAction { id: None, condition, actions })
                if is_sync_id(catalogue, target) =>
            {
                let id = Box::new(SyncId { keyword: target.name.clone(), number: (**value).clone() });
                previous.kind =
                    StatementKind::SyncAction { id: Some(id), condition: condition.clone(), actions: actions.clone() };
                true
            }
            (StatementKind::Command(command), StatementKind::Call(call))
                if command.name == "REPEAT" && command.arguments.is_empty() =>
            {
                match &call.callee {
                    Callee::Program(label) if call.arguments.is_empty() => {
                        previous.kind = StatementKind::RepeatSection { start: label.clone(), end: None, count: None };
                        true
                    }
                    _ => false,
                }
            }
            (StatementKind::RepeatSection { end, count: None, .. }, StatementKind::Call(call)) if end.is_none() => {
                match &call.callee {
                    Callee::Program(label) if call.arguments.is_empty() => {
                        *end = Some(label.clone());
                        true
                    }
                    _ => false,
                }
            }
            (StatementKind::RepeatSection { count, .. }, StatementKind::Word(word))
                if count.is_none() && is_count(catalogue, word) =>
            {
                *count = word.value.clone().map(|value| match value {
                    WordValue::Literal(number) => Box::new(Expr { kind: ExprKind::Number(number), range: word.range }),
                    WordValue::Expr { expr, .. } => expr,
                });
                true
            }
            _ => false,
        };
        if taken {
            previous.range = previous.range.cover(statement.range);
        } else {
            attached.push(statement);
        }
    }
    attached
}

/// Whether `command` is a block-only code that reads `word`'s address (a
/// frame: `TRANS X10`).
fn takes_word(catalogue: &Catalogue, command: &Command, word: &Word) -> bool {
    catalogue.word_code(&command.name).is_some_and(|code| {
        code.modality == Modality::Block && code.allows.iter().any(|a| a.eq_ignore_ascii_case(&word.address))
    })
}

/// Whether `target` is the number of a synchronous action (`ID`, `IDS`).
fn is_sync_id(catalogue: &Catalogue, target: &Place) -> bool {
    target.kind == PlaceKind::User
        && target.indices.is_empty()
        && catalogue.keyword(&target.name).is_some_and(|keyword| keyword.kind == KeywordKind::SynchronousAction)
}

/// Whether `word` is the repetition count (`P3`).
fn is_count(catalogue: &Catalogue, word: &Word) -> bool {
    catalogue.address(&word.address).is_some_and(|address| address.role == AddressRole::Count)
}

fn malformed(range: TextRange) -> Expr {
    Expr { kind: ExprKind::Malformed, range }
}

fn number_expr(text: &str, range: TextRange) -> Expr {
    let kind = Number::parse(None, text).map_or(ExprKind::Malformed, ExprKind::Number);
    Expr { kind, range }
}

/// The expression a child is, if it is one.
fn expr_child(catalogue: &Catalogue, child: GreenRef<'_>, range: TextRange) -> Option<Expr> {
    match child {
        NodeOrToken::Node(node) => match kind(node.kind()) {
            SyntaxKind::LITERAL
            | SyntaxKind::NAME_REF
            | SyntaxKind::INDEX_EXPR
            | SyntaxKind::PARAM_REF
            | SyntaxKind::PREFIX_EXPR
            | SyntaxKind::BIN_EXPR
            | SyntaxKind::BRACKET_EXPR
            | SyntaxKind::ARG_LIST
            | SyntaxKind::CALL_EXPR => Some(lower_expr(catalogue, node, range)),
            _ => None,
        },
        NodeOrToken::Token(_) => None,
    }
}

fn lower_expr(catalogue: &Catalogue, node: &GreenNodeData, range: TextRange) -> Expr {
    let operands = || items(node, range).filter_map(|(r, c)| expr_child(catalogue, c, r));
    let expr_kind = match kind(node.kind()) {
        SyntaxKind::LITERAL => literal(node, range),
        SyntaxKind::NAME_REF => match name_of(node, range).as_str() {
            "TRUE" => ExprKind::Bool(true),
            "FALSE" => ExprKind::Bool(false),
            _ => ExprKind::Name(place(catalogue, node, range)),
        },
        SyntaxKind::INDEX_EXPR | SyntaxKind::PARAM_REF => ExprKind::Name(place(catalogue, node, range)),
        SyntaxKind::BRACKET_EXPR => return operands().next().unwrap_or_else(|| malformed(range)),
        SyntaxKind::ARG_LIST => ExprKind::List(list_values(catalogue, node, range)),
        SyntaxKind::PREFIX_EXPR => {
            let op = match items(node, range).next().map(|(_, c)| (kind(c.kind()), upper(c))) {
                Some((SyntaxKind::MINUS, _)) => UnaryOp::Minus,
                Some((SyntaxKind::CONCAT, _)) => UnaryOp::ToString,
                Some((_, Some(name))) if name == "NOT" => UnaryOp::Not,
                Some((_, Some(name))) if name == "B_NOT" => UnaryOp::BitNot,
                _ => UnaryOp::Plus,
            };
            match operands().next() {
                Some(operand) => ExprKind::Unary(op, Box::new(operand)),
                None => ExprKind::Malformed,
            }
        }
        SyntaxKind::BIN_EXPR => {
            let op = items(node, range).find_map(|(_, c)| c.into_token().and_then(binary_op));
            let mut operands = operands();
            match (op, operands.next(), operands.next()) {
                (Some(op), Some(lhs), Some(rhs)) => ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                _ => ExprKind::Malformed,
            }
        }
        SyntaxKind::CALL_EXPR => ExprKind::Call {
            name: items(node, range).next().and_then(|(_, c)| upper(c)).unwrap_or_default(),
            arguments: arguments_of(catalogue, node, range),
        },
        _ => ExprKind::Malformed,
    };
    Expr { kind: expr_kind, range }
}

fn binary_op(token: &GreenTokenData) -> Option<BinaryOp> {
    Some(match kind(token.kind()) {
        SyntaxKind::PLUS => BinaryOp::Add,
        SyntaxKind::MINUS => BinaryOp::Sub,
        SyntaxKind::STAR => BinaryOp::Mul,
        SyntaxKind::SLASH => BinaryOp::Div,
        SyntaxKind::CONCAT => BinaryOp::Concat,
        SyntaxKind::EQ_EQ => BinaryOp::Eq,
        SyntaxKind::NEQ => BinaryOp::Ne,
        SyntaxKind::LT => BinaryOp::Lt,
        SyntaxKind::LT_EQ => BinaryOp::Le,
        SyntaxKind::GT => BinaryOp::Gt,
        SyntaxKind::GT_EQ => BinaryOp::Ge,
        SyntaxKind::COLON => BinaryOp::Chain,
        SyntaxKind::IDENT => match token.text().to_ascii_uppercase().as_str() {
            "DIV" => BinaryOp::IntDiv,
            "MOD" => BinaryOp::Mod,
            "B_AND" => BinaryOp::BitAnd,
            "B_XOR" => BinaryOp::BitXor,
            "B_OR" => BinaryOp::BitOr,
            "AND" => BinaryOp::And,
            "XOR" => BinaryOp::Xor,
            "OR" => BinaryOp::Or,
            _ => return None,
        },
        _ => return None,
    })
}

/// A `LITERAL`: a number (two number tokens are a doubled point) or a
/// quoted text: `"…"` a string, `'H1F'` and `'B101'` constants.
fn literal(node: &GreenNodeData, range: TextRange) -> ExprKind {
    let mut tokens = items(node, range).filter_map(|(_, c)| c.into_token());
    let (Some(token), None) = (tokens.next(), tokens.next()) else { return ExprKind::Malformed };
    let text = token.text();
    if kind(token.kind()) == SyntaxKind::NUMBER {
        return Number::parse(None, text).map_or(ExprKind::Malformed, ExprKind::Number);
    }
    let quote = &text[..1];
    let inner = text[1..].strip_suffix(quote).unwrap_or(&text[1..]);
    if quote == "'" {
        let radix = match inner.as_bytes().first().map(u8::to_ascii_uppercase) {
            Some(b'H') => Some(16),
            Some(b'B') => Some(2),
            _ => None,
        };
        if let Some(radix) = radix {
            return i64::from_str_radix(&inner[1..], radix).map_or(ExprKind::Malformed, ExprKind::Integer);
        }
    }
    ExprKind::String(inner.to_owned())
}

#[cfg(test)]
pub(crate) mod tests;
