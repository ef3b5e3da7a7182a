//! The Siemens Sinumerik dialect: lexer, parser and incremental reparser.
//!
//! Sources: the digest of seed 004 (§1.2-1.4, §2, §7); the line references
//! `004:N` point into the seed. Where the seed is silent the forms follow
//! the Siemens programming manual, marked *assumption* below.
//!
//! # Blocks
//!
//! A block is one line, with its line break (004:213). Nothing spans lines:
//! comments `;…` and strings `"…"` end at the line's end, so every line
//! start is a block start and an edit reparses only the lines it touches.
//!
//! ```text
//! block     := [skip] [header | number] [label] statement* [comment] [newline]
//! skip      := "/" [digit]                        block skip, with its level
//! header    := "%" name                           `%_N_PART_MPF`, a file header
//! number    := ("N" | ":") digits                 `N10`, the main block `:10`
//! label     := name ":"                           `LOOP1:`
//! ```
//!
//! # Statements
//!
//! ```text
//! word      := letter [sign] number               `X-12.5`, `G641`, `M17`
//!            | letter [digits] "=" expr           `X=R1+5`, `A3=1`, `X1=X`, `T="DRILL"`
//! assign    := target "=" expr                    `R1=5`, `R[R1+2]=0`, `A[1,2]=3`,
//!                                                 `$TC_DP1[1,1]=120`, `G[8]=2`, `CR=10`
//! call      := name [args]                        `TRAORI`, `CYCLE81(10,0,2)`, `MSG("…")`
//!            | ("L" | "M") digits args             `L140(1)`, `M6(T1)`: numbered subprograms
//!            | "CALL" expr ["BLOCK" expr "TO" expr]
//!            | "PCALL" path [args]                `PCALL /_N_CST_DIR/_N_SUB_SPF(1)`
//! macro     := "DEFINE" name "AS" text            the text is kept as tokens
//!            | "MCALL" [name [args]]
//! def       := "DEF" [NCK|CHAN] type decl {"," decl}
//! decl      := name ["[" expr {"," expr} "]"] ["=" expr]
//! type      := INT | REAL | BOOL | CHAR | STRING ["[" expr "]"] | AXIS | FRAME
//! proc      := "PROC" name ["(" [param {"," param}] ")"] {name}   attributes SAVE, DISPLOF, …
//! extern    := "EXTERN" name ["(" [param {"," param}] ")"]
//! param     := ["VAR"] type [name] ["[" dims "]"]
//! control   := "IF" expr [jump] | "ELSE" | "ENDIF"
//!            | "WHILE" expr | "ENDWHILE" | "FOR" assign "TO" expr | "ENDFOR"
//!            | "REPEAT" | "UNTIL" expr | "LOOP" | "ENDLOOP"
//!            | "CASE" expr "OF" {(value | "DEFAULT") jump}
//!            | jump
//! jump      := ("GOTO" | "GOTOF" | "GOTOB" | "GOTOC") (block-number | expr) | "GOTOS"
//! sync      := [("WHEN" | "WHENEVER" | "EVERY" | "FROM") expr] "DO" statement*
//! ```
//!
//! Names and addresses (004:1444-1450): a letter followed by a letter or
//! `_`, or `_` itself, starts a name (`CYCLE800`, `CUT3DC`, `_N_SUB_SPF`,
//! `OTOL`); any other letter is an address. So `X10` is a word, `A3=1` an
//! address with its extension, `X10Y20` two words. `$` and a name is a
//! system variable. Case does not matter (004:1450).
//!
//! What the tree leaves to the lowering, which knows the catalogue:
//!
//! * A name followed by `=` is an `ASSIGN` whether it is a variable
//!   (`DELKA=5`) or a multi-letter address (`CR=10`, `SD=3`, `AP=90`,
//!   `CHF=2`): only the catalogue tells them apart.
//! * A name on its own is a `CALL_STMT` whether it is a command (`TRAORI`,
//!   `BSPLINE`, `SOFT`, `G64`-like words) or a subprogram (`PROFIL`,
//!   `_N_SUB_SPF`); its repetition count `P3` is the next word.
//! * Frame commands keep their axis words as the next statements of the
//!   block: `TRANS X10 Y20` is a call and two words (digest §2.2).
//! * Control structures stay one statement per block (`IF`, `ELSE`,
//!   `ENDIF`, `LOOP_START`, `LOOP_END` …); lowering matches them, so an
//!   unbalanced structure is no syntax error and an edit inside a loop
//!   reparses one line.
//! * In an expression a letter is a name (`X`, the formal parameter of
//!   004:1506, or the axis `X1`) unless it is `R` with a number or index;
//!   `TRUE`, `FALSE` and labels are names too.
//! * A jump target `N10` is a `BLOCK_NUMBER`; any other target is an
//!   expression: a name is a label, a string expression is computed.
//!
//! Operators and their priority follow digest §2.4 (the Siemens table):
//! `NOT`, signs; `* / DIV MOD`; `+ -`; `B_AND`; `B_XOR`; `B_OR`; `AND`;
//! `XOR`; `OR`; `<<`; comparisons. A leading `<<` converts to a string
//! (`MSG(<<R1)`), `:` chains frames, and `(1,2,3)` is a list of values
//! (an array's initial values), an `ARG_LIST`.
//!
//! Assumptions: the scopes `NCK`/`CHAN` after `DEF`, `FRAME`, `LOOP`,
//! `REPEAT`/`UNTIL`, `GOTOC`/`GOTOS`, synchronous actions, quoted
//! constants `'H1F'` and exponents `1EX3` are not in the seed and follow
//! the Siemens manual. A lower-case address is no error: names are
//! case-insensitive (004:1450) and the seed gives no rule for addresses.

mod lexer;
mod parser;

use crate::{
    Parse, SyntaxNode, TextEdit,
    line_blocks::{self, LineDialect},
};

pub(crate) use parser::parse_source_file;

/// Parses `new_text`, the result of applying `edit` to the text of `old`,
/// reusing every line the edit cannot have changed; `None` when the whole
/// text must be parsed again. No edit is refused: nothing spans lines.
pub(crate) fn reparse_blocks(old: &Parse, edit: &TextEdit, new_text: &str) -> Option<Parse> {
    let dialect = LineDialect { edit_ok: |_: &SyntaxNode| true, region_ok: |_: &SyntaxNode, _: &str| true };
    let (green, errors, omitted) = line_blocks::reparse_line_blocks::<parser::Parser<'_>, _, _>(
        (old.green(), old.errors(), old.omitted()),
        edit,
        new_text,
        dialect,
    )?;
    Some(Parse { green, errors: errors.into(), omitted: omitted.into(), dialect: old.dialect })
}
