//! The entry types of the catalogue, as the data files spell them.
//!
//! Every entry carries the same documentation fields (title, summary,
//! details, example, source); the [`entry!`] macro adds them, so that the
//! files are checked strictly (`deny_unknown_fields`) and hover text is
//! rendered the same way for every kind of entry.

use serde::Deserialize;

/// The documentation every entry has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Doc<'a> {
    /// A short name: "Rapid positioning".
    pub title: &'a str,
    /// One sentence: what it is and does.
    pub summary: &'a str,
    /// Further paragraphs in Markdown; may be empty.
    pub details: &'a str,
    /// A one-line program example.
    pub example: Option<&'a str>,
    /// Where the manual describes it, by chapter and section name.
    pub source: &'a str,
}

/// Entries that have documentation.
pub trait Documented {
    fn doc(&self) -> Doc<'_>;
}

macro_rules! entry {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $($(#[$field_meta:meta])* pub $field:ident : $ty:ty,)*
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            $($(#[$field_meta])* pub $field: $ty,)*
            pub title: String,
            pub summary: String,
            #[serde(default)]
            pub details: String,
            #[serde(default)]
            pub example: Option<String>,
            pub source: String,
        }

        impl Documented for $name {
            fn doc(&self) -> Doc<'_> {
                Doc {
                    title: &self.title,
                    summary: &self.summary,
                    details: &self.details,
                    example: self.example.as_deref(),
                    source: &self.source,
                }
            }
        }
    };
}

/// What the codes of a function letter do, as ISO programming names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FunctionKind {
    /// How the next moves run: motion, plane, units, cycles (G).
    Preparatory,
    /// What the machine does besides moving: spindle, coolant, stops (M).
    Miscellaneous,
}

/// Whether a function or word holds until changed or only in its block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Modality {
    /// Holds until another value (or another code of the group) replaces it.
    Modal,
    /// Valid only in the block where it is written (`x` in the dictionary).
    Block,
}

fn yes() -> bool {
    true
}

entry! {
    /// A group of G or M functions, of which one may be written per block.
    pub struct Group {
        /// `G0` … `G11`, `M1` … `M14`; Sinumerik's G groups 1 … n are `G1` …
        /// `Gn`, whatever their members are written as.
        pub id: String,
        /// The code set at reset and by M02/M30 (the `+` code, or the
        /// priority block's where the dictionary marks none).
        #[serde(default)]
        pub default: Option<String>,
        /// Where the default comes from, when it is not the dictionary's `+`.
        #[serde(default)]
        pub default_note: Option<String>,
        /// The machine builder defines the codes (M10–M14): any code of the
        /// open range that no other group lists belongs here.
        #[serde(default)]
        pub open: bool,
        /// The first and last code of a range whose codes no group lists
        /// belong here (`["M10", "M99"]` for M14).
        #[serde(default)]
        pub takes_unlisted: Option<[String; 2]>,
        /// The machine constant that defines an open group (`R56` for M10).
        #[serde(default)]
        pub configured_by: Option<String>,
    }
}

entry! {
    /// A G or M code, or a word that stands in a G group like one
    /// (Sinumerik's `BSPLINE`, `SOFT`, `TRANS`).
    pub struct Code {
        /// Letter and digits (`G00`, `M30`; Sinumerik `G0`, `G641`), or a
        /// word ([`Code::is_word`]).
        pub code: String,
        /// Its number inside its group, from 1, where the control numbers
        /// them: Sinumerik's `$P_GG[n]` reads it and `G[n]=k` selects by it.
        #[serde(default)]
        pub index: Option<u32>,
        /// How it is written with what it takes, one form per line, where
        /// it takes more than the addresses of `requires` and `allows`
        /// (`TRANS X… Y… Z…`, `POLY PO[X]=(…)`).
        #[serde(default)]
        pub syntax: Vec<String>,
        /// The group; `None` for codes the manual uses outside the groups.
        #[serde(default)]
        pub group: Option<String>,
        pub modality: Modality,
        /// Marked `+` in the dictionary.
        #[serde(default)]
        pub reset_default: bool,
        /// Listed in the address dictionary (false for codes only the text uses).
        #[serde(default = "yes")]
        pub in_dictionary: bool,
        /// Addresses that must be written in the same block (`L` for G71).
        #[serde(default)]
        pub requires: Vec<String>,
        /// Addresses the function reads besides the required ones.
        #[serde(default)]
        pub allows: Vec<String>,
        /// Codes of other groups this one cancels or resets.
        #[serde(default)]
        pub cancels: Vec<String>,
        /// Units of the values it uses, where that matters.
        #[serde(default)]
        pub units: Option<String>,
        /// An option of the control (`#` in the Haas table): the machine
        /// needs it.
        #[serde(default)]
        pub optional: bool,
        /// The only machine models that have it (`SL-30`); empty: all.
        #[serde(default)]
        pub machines: Vec<String>,
        /// For service use only, not for part programs.
        #[serde(default)]
        pub service: bool,
        /// False where the manual gives the code no usable description:
        /// an empty or doubtful table row, no format.
        #[serde(default = "yes")]
        pub described: bool,
        /// Needs a driven (live) tool.
        #[serde(default)]
        pub live_tool: bool,
    }
}

impl Code {
    /// Written as a word (`BSPLINE`, `CUT3DC`) rather than a letter and a
    /// number.
    pub fn is_word(&self) -> bool {
        crate::split_code(&self.code).is_none()
    }
}

/// What an address does in the grammar and the program.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AddressRole {
    /// `N`: starts a block.
    BlockNumber,
    /// `R`: parameter assignment `R1=…` and reference `XR1`.
    Parameter,
    /// `G`, `M`.
    Function,
    /// A coordinate axis: X, Y, Z and the letters of axes 4–6.
    Axis,
    /// `I`, `J`, `K`: circle centre and thread data.
    Interpolation,
    Feed,
    Speed,
    Tool,
    /// `D`: entry of the tool-offset table.
    Offset,
    /// `&`: length-compensation assignment.
    LengthCompensation,
    /// `Q`: repetitions or dwell.
    Count,
    /// `L`: subprogram, macrocycle or jump target.
    Label,
    /// `H`, `P`.
    Auxiliary,
    /// `E`: thread lead-in length.
    ThreadLeadIn,
    /// `/`.
    BlockSkip,
    /// `%`.
    ProgramNumber,
    /// `*`.
    ProgramEnd,
    /// Chamfer or rounding of the corner at the block's end (`CHF`, `RND`).
    Corner,
    /// A spline's degree, point weight or knot interval (`SD`, `PW`, `PL`).
    Spline,
    /// Tool orientation: direction vector, angles, lead and tilt (`A3`, `LEAD`).
    Orientation,
    /// A tolerance or smoothing distance of the path (`OTOL`, `ADIS`).
    Tolerance,
}

/// Whether a word carries a unit (the manual's "dimensional word").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Dimensional {
    Yes,
    No,
    /// Depends on the function (Q: count or dwell).
    Depends,
    /// The manual does not classify it.
    Unclassified,
}

entry! {
    /// An address letter (or `&`, `/`, `%`, `*`), or an address of several
    /// characters (Sinumerik's `CR`, `A3`, `OTOL`), which takes its value
    /// after `=`.
    pub struct Address {
        pub letter: String,
        pub role: AddressRole,
        /// For a function letter, what its codes do.
        #[serde(default)]
        pub function: Option<FunctionKind>,
        pub dimensional: Dimensional,
        /// May carry a sign.
        #[serde(default)]
        pub signed: bool,
        /// The maximal block format, as printed: `+5.3`, `8`, `2..3 or 5`.
        #[serde(default)]
        pub format: Option<String>,
        /// Digits before the point the format allows.
        #[serde(default)]
        pub int_digits: Option<u8>,
        /// Digits after the point the format allows (0: no point).
        #[serde(default)]
        pub frac_digits: Option<u8>,
        /// Digits allowed when the value is written without a decimal
        /// point, where the format has a second form (F: 5, R: 8).
        #[serde(default)]
        pub int_digits_without_point: Option<u8>,
        /// Smallest and largest value, as written (`-69999.999`).
        #[serde(default)]
        pub min: Option<String>,
        #[serde(default)]
        pub max: Option<String>,
        /// How the value is read: unit with and without a decimal point.
        #[serde(default)]
        pub units: Option<String>,
        /// May be replaced by a parameter (`XR1`).
        pub substitutable: bool,
        /// `None` where the manual does not say.
        #[serde(default)]
        pub modality: Option<Modality>,
        /// A letter the machine configuration may assign to axis 4, 5 or 6.
        #[serde(default)]
        pub configurable_axis: bool,
        /// Listed in the address dictionary (false for `E`, which only the
        /// text uses).
        #[serde(default = "yes")]
        pub in_dictionary: bool,
        /// `min` and `max` as numbers, filled in when the catalogue loads.
        #[serde(skip)]
        pub bounds: Option<(f64, f64)>,
    }
}

/// How a range of program parameters may be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ParameterStatus {
    Ordinary,
    /// Has a special role but may be used (R0–R4 in `G92 D`, R5–R8).
    Special,
    /// Reserved for future use: better not used.
    NotRecommended,
    /// Must not be written.
    Reserved,
}

entry! {
    /// What holds for all program parameters R0–R95 (or a dialect's
    /// numbered variables).
    pub struct ParameterOverview {
        /// Number of parameters (96).
        pub count: u32,
        /// What stands between an address and a parameter as its value:
        /// nothing (`XR1`) or `=` (Sinumerik `X=R1`).
        #[serde(default)]
        pub value_separator: String,
        /// What a parameter's number is written after: `R` (`R12`), `#`.
        #[serde(default = "letter_r")]
        pub written: String,
        /// What the dialect calls them: "program parameter", "macro variable".
        #[serde(default = "program_parameter")]
        pub noun: String,
    }
}

/// What a dialect calls its machine constants and where the control keeps
/// them: the words hover and `ncc explain` use.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantTerms {
    /// What a constant's number is written after: `R` (`R39`), `Setting `.
    pub written: String,
    /// "machine constant", "setting".
    pub noun: String,
    /// One sentence on where the control keeps them.
    pub kept: String,
}

impl Default for ConstantTerms {
    /// The CNC8x6's.
    fn default() -> ConstantTerms {
        ConstantTerms {
            written: "R".to_owned(),
            noun: "machine constant".to_owned(),
            kept: "A machine constant: configuration of the control (TAB0.REK), not a program parameter.".to_owned(),
        }
    }
}

fn letter_r() -> String {
    "R".to_owned()
}

fn program_parameter() -> String {
    "program parameter".to_owned()
}

entry! {
    /// Program parameters with a common role: `R5`–`R8`, `R95`, …
    pub struct ParameterRange {
        pub first: u32,
        pub last: u32,
        pub status: ParameterStatus,
    }
}

/// One field of a machine constant encoded digit by digit.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DecadeField {
    /// `"1"`, `"1-4"`, `"8"`: decade 1 is the rightmost digit.
    pub decades: String,
    pub meaning: String,
}

entry! {
    /// A machine constant (`R39`, `R232`, …): configuration of the control,
    /// not a program parameter.
    pub struct MachineConstant {
        pub number: u32,
        /// The name a program reads it by, after the prefix of its kind
        /// (Sinumerik `MM_NUM_R_PARAM` in `$MC_MM_NUM_R_PARAM`).
        #[serde(default)]
        pub name: Option<String>,
        /// For a run of constants described together (`R356`–`R381`).
        #[serde(default)]
        pub last: Option<u32>,
        #[serde(default)]
        pub unit: Option<String>,
        #[serde(default)]
        pub default: Option<String>,
        #[serde(default)]
        pub decades: Vec<DecadeField>,
    }
}

entry! {
    /// A parameter-arithmetic operation (control word `CCAABBTT`, CC = code),
    /// or an operator or function of a dialect's expressions (`SIN`, `EQ`).
    pub struct Operation {
        /// How tightly the operator binds, 1 the tightest; binary operators
        /// of one level go left to right.
        #[serde(default)]
        pub precedence: Option<u8>,
        /// The operation code; for expression operators, their number in
        /// the file (1, 2, …).
        pub code: u32,
        /// How an expression operator is written (`+`, `SIN`, `EQ`); `None`
        /// for operations chosen by code.
        #[serde(default)]
        pub symbol: Option<String>,
        /// False for the code the manual leaves undefined (43).
        #[serde(default = "yes")]
        pub defined: bool,
        /// The operands, `*` where double precision is possible: `op1*, op2*`.
        pub operands: String,
        /// What is stored: `target* := op1 + op2`.
        pub result: String,
        /// Stores 73/78 or gates the following operations.
        #[serde(default)]
        pub conditional: bool,
        /// Real (`+` sign) and integer (`-` sign) behaviour, where it differs.
        #[serde(default)]
        pub modes: Option<String>,
        /// Failure cases (division by zero, …) and what the manual says of them.
        #[serde(default)]
        pub errors: Option<String>,
    }
}

/// Which machine family a fixed cycle belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Flavour {
    Milling,
    Lathe,
}

/// One input of a fixed cycle.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CycleParameter {
    /// The program parameter number (`0` for R0).
    pub r: u32,
    pub meaning: String,
    #[serde(default)]
    pub unit: Option<String>,
}

/// One argument of a cycle called like a procedure (Sinumerik
/// `CYCLE81(RTP, RFP, …)`), in order.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CycleArgument {
    pub name: String,
    /// `REAL`, `INT`, `STRING[32]`, …
    #[serde(rename = "type")]
    pub ty: String,
    pub meaning: String,
    #[serde(default)]
    pub unit: Option<String>,
}

/// One address word a canned cycle reads from its own block (`P`, `U`, `D`).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CycleAddress {
    pub letter: String,
    pub meaning: String,
    #[serde(default)]
    pub unit: Option<String>,
}

entry! {
    /// A fixed cycle (G81–G89) of the milling or lathe cycle files, or a
    /// canned cycle called with its address words.
    pub struct Cycle {
        pub code: String,
        pub flavour: Flavour,
        /// The `$PC` file it comes from.
        #[serde(default)]
        pub file: Option<String>,
        /// The program parameters it reads (cycles called through R parameters).
        #[serde(default, rename = "parameter")]
        pub parameters: Vec<CycleParameter>,
        /// The address words it reads from its block (cycles called with words).
        #[serde(default, rename = "address")]
        pub addresses: Vec<CycleAddress>,
        /// Its arguments in order (cycles called like a procedure).
        #[serde(default, rename = "argument")]
        pub arguments: Vec<CycleArgument>,
        /// The machine constants (Haas: Settings) that change what it does.
        #[serde(default)]
        pub machine_constants: Vec<u32>,
        /// What a hole cycle does to the hole at the current position; it
        /// leaves the tool above that hole.
        #[serde(default)]
        pub hole: Option<HoleOperation>,
    }
}

/// What a hole cycle does to its hole, in the order a hole is made:
/// drilled, then bored or tapped, then reamed (004:468-470).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HoleOperation {
    Drill,
    Bore,
    Tap,
    Ream,
}

impl HoleOperation {
    /// Its place in the order: an operation of a lower stage after one of
    /// a higher stage at the same hole is out of order.
    pub fn stage(self) -> u8 {
        match self {
            HoleOperation::Drill => 0,
            HoleOperation::Bore | HoleOperation::Tap => 1,
            HoleOperation::Ream => 2,
        }
    }

    /// The verb, as in "drilled after reamed".
    pub fn done(self) -> &'static str {
        match self {
            HoleOperation::Drill => "drilled",
            HoleOperation::Bore => "bored",
            HoleOperation::Tap => "tapped",
            HoleOperation::Ream => "reamed",
        }
    }
}

/// What kind of word of the language a keyword is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum KeywordKind {
    /// Defines or declares a name: `DEF`, `PROC`, `EXTERN`.
    Declaration,
    /// A data type: `REAL`, `STRING`.
    Type,
    /// A constant value: `TRUE`.
    Literal,
    /// Structures the flow: `IF`, `WHILE`, `FOR`, `CASE`.
    Control,
    /// Jumps to a label or block number: `GOTOF`.
    Jump,
    /// Calls or leaves a subprogram: `MCALL`, `RET`.
    Subprogram,
    /// Switches a kinematic transformation: `TRAORI`.
    Transformation,
    /// Part of a synchronous action: `ID`, `WHENEVER`, `DO`.
    SynchronousAction,
    /// A statement of its own: `STOPRE`.
    Statement,
}

entry! {
    /// A word of a dialect's language that is neither an address nor a
    /// code of a group: a declaration, type, control structure, jump, …
    /// (Sinumerik `DEF`, `GOTOF`, `TRAORI`).
    pub struct Keyword {
        pub word: String,
        pub kind: KeywordKind,
        /// How it is written, one form per line (`DEF <type> <name>[=<value>]`).
        pub syntax: Vec<String>,
        /// The words it goes with (`ENDIF` for `IF`).
        #[serde(default)]
        pub related: Vec<String>,
    }
}

/// One parameter of a function or procedure, in order.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FunctionParameter {
    pub name: String,
    /// `REAL`, `INT`, `STRING`, `VAR INT` (by reference), `REAL…` (a list).
    #[serde(rename = "type")]
    pub ty: String,
    pub meaning: String,
    /// May be left out.
    #[serde(default)]
    pub optional: bool,
}

entry! {
    /// A predefined function (`SIN`, returns a value) or procedure (`WRITE`,
    /// a statement of its own) of a dialect's language.
    pub struct Function {
        pub name: String,
        #[serde(default, rename = "parameter")]
        pub parameters: Vec<FunctionParameter>,
        /// The type of the value; `None` for a procedure.
        #[serde(default)]
        pub returns: Option<String>,
    }
}

impl Function {
    /// `SIN(REAL x) → REAL`, `WRITE(VAR INT error, STRING file, STRING line)`.
    pub fn signature(&self) -> String {
        let mut text = format!("{}(", self.name);
        for (index, parameter) in self.parameters.iter().enumerate() {
            let separator = if index == 0 { "" } else { ", " };
            let parameter_text = format!("{} {}", parameter.ty, parameter.name);
            if parameter.optional {
                text.push_str(&format!("[{separator}{parameter_text}]"));
            } else {
                text.push_str(&format!("{separator}{parameter_text}"));
            }
        }
        text.push(')');
        if let Some(returns) = &self.returns {
            text.push_str(&format!(" → {returns}"));
        }
        text
    }
}

/// Whether a program may write a system variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Access {
    Read,
    ReadWrite,
}

entry! {
    /// A system variable (Sinumerik `$P_F`, `$AA_IM[X]`): a value of the
    /// control with a fixed meaning.
    pub struct SystemVariable {
        /// With its prefix and without an index: `$P_GG`.
        pub name: String,
        /// `REAL`, `INT`, `BOOL`, `STRING`, …
        #[serde(rename = "type")]
        pub ty: String,
        pub access: Access,
        /// What the index in brackets names (`G group number`, `axis`);
        /// `None` when it takes none.
        #[serde(default)]
        pub index: Option<String>,
        /// A main-run value: current, not programmed. Outside a synchronous
        /// action, reading it stops preprocessing until the run catches up.
        #[serde(default)]
        pub main_run: bool,
    }
}

entry! {
    /// What the variables whose names start with a prefix are (`$P_`:
    /// programmed values), so that one the catalogue does not list is
    /// still known for a system variable.
    pub struct VariablePrefix {
        /// `$P_`, `$AA_`, `$MC_`.
        pub prefix: String,
        /// Machine or setting data: the name after the prefix is a machine
        /// constant's (`$MC_MM_NUM_R_PARAM`).
        #[serde(default)]
        pub machine_data: bool,
    }
}
