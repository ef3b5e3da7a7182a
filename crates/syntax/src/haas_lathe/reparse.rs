//! Incremental reparsing of Haas programs: the shared reparse of line
//! blocks (`line_blocks`), refused where an edit could move a tape mark
//! `%`.

use super::parser;
use crate::{
    Parse, SyntaxKind, SyntaxNode, TextEdit,
    line_blocks::{LineDialect, reparse_line_blocks},
    runs::deleted_text,
};

pub(crate) fn reparse_blocks(old: &Parse, edit: &TextEdit, new_text: &str) -> Option<Parse> {
    let dialect = LineDialect {
        edit_ok: |root: &SyntaxNode| !edit.insert.contains('%') && !deleted_text(root, edit.delete).contains('%'),
        region_ok: |root: &SyntaxNode, region: &str| {
            // A line of the region that now starts with `%` would be a tape
            // mark. Without an opening mark, blanking the lines before a
            // `%` line would make it the opening mark.
            let body_start =
                root.children().find(|n| n.kind() == SyntaxKind::BLOCK_RUN).map(|n| n.text_range().start());
            let opening = body_start.is_some_and(|start| {
                root.children().any(|n| n.kind() == SyntaxKind::TAPE_MARK && n.text_range().end() <= start)
            });
            !region.contains('%') && (opening || !region.trim().is_empty())
        },
    };
    let (green, errors, omitted) = reparse_line_blocks::<parser::Parser<'_>, _, _>(
        (old.green(), old.errors(), old.omitted()),
        edit,
        new_text,
        dialect,
    )?;
    Some(Parse { green, errors: errors.into(), omitted: omitted.into(), dialect: old.dialect })
}
