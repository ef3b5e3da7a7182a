//! Any text in any dialect and style: formatting and renumbering never
//! panic; formatting keeps every line and is idempotent.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ncc_analysis::{
    AnalysisHost, Config, Dialect, FormatConfig, LetterCase, NumberStyle, TextEdit, WordOrder, WordSpacing,
};

fn applied(text: &str, edits: &[TextEdit]) -> String {
    let mut text = text.to_owned();
    for edit in edits.iter().rev() {
        edit.apply(&mut text);
    }
    text
}

fuzz_target!(|data: &[u8]| {
    let Some((&choice, rest)) = data.split_first() else { return };
    let text = String::from_utf8_lossy(rest).into_owned();
    let dialect = [Dialect::Cnc8x6, Dialect::HaasLathe, Dialect::Sinumerik][usize::from(choice % 3)];
    let style = FormatConfig {
        spacing: if choice & 4 == 0 { WordSpacing::One } else { WordSpacing::None },
        case: if choice & 8 == 0 { LetterCase::Keep } else { LetterCase::Upper },
        numbers: if choice & 16 == 0 { NumberStyle::Keep } else { NumberStyle::Trim },
        word_order: if choice & 32 == 0 { WordOrder::Keep } else { WordOrder::Standard },
        indent: (choice & 64 != 0).then_some(2),
    };
    let mut host = AnalysisHost::in_dialect(dialect, Config { format: style, ..Config::default() });
    let file = host.add_file("main", text.as_str());
    let formatted = applied(&text, &host.analysis().format(file, None));
    assert_eq!(formatted.matches('\n').count(), text.matches('\n').count());
    host.set_text(file, formatted.as_str());
    assert_eq!(host.analysis().format(file, None), Vec::new(), "idempotent");
    if let Ok(edits) = host.analysis().renumber(file, u64::from(choice), 1 + u64::from(choice >> 4)) {
        let _ = applied(&formatted, &edits);
    }
});
