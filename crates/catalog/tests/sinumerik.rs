//! The text `ncc explain` and hover show for Sinumerik's entries, a few of
//! each kind. The facts of the catalogue are checked in the crate's unit
//! tests (`src/tests/sinumerik.rs`).

use ncc_catalog::Dialect;

fn explain(query: &str) -> String {
    let catalogue = Dialect::Sinumerik.catalogue();
    match catalogue.explain(query) {
        Ok(items) => items.iter().map(|item| item.markdown(catalogue)).collect::<Vec<_>>().join("\n"),
        Err(not_found) => format!("not found: {not_found:?}\n"),
    }
}

#[test]
fn explain_snapshots() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/explain/sinumerik");
    for (query, file) in [
        ("BSPLINE", "BSPLINE.md"),
        ("G642", "G642.md"),
        ("TRANS", "TRANS.md"),
        ("G550", "G550.md"),
        ("group:G1", "group_G1.md"),
        ("M17", "M17.md"),
        ("CR", "CR.md"),
        ("R37", "R37.md"),
        ("DEF", "DEF.md"),
        ("GOTOF", "GOTOF.md"),
        ("SUBSTR", "SUBSTR.md"),
        ("WRITE", "WRITE.md"),
        ("<<", "concatenation.md"),
        ("$P_GG[6]", "P_GG.md"),
        ("$P_XYZ", "P_XYZ.md"),
        ("$MN_MM_NUM_R_PARAM", "MM_NUM_R_PARAM.md"),
        ("CYCLE81", "CYCLE81.md"),
        ("CYCLE832", "CYCLE832.md"),
    ] {
        expect_test::expect_file![dir.join(file)].assert_eq(&explain(query));
    }
}

#[test]
fn unknown_words_get_suggestions() {
    let catalogue = Dialect::Sinumerik.catalogue();
    let not_found = catalogue.explain("GOTOX").unwrap_err();
    assert!(not_found.suggestions.iter().any(|s| s == "GOTOF" || s == "GOTO"), "{not_found:?}");
    let not_found = catalogue.explain("BSPLIN").unwrap_err();
    assert_eq!(not_found.suggestions.first().map(String::as_str), Some("BSPLINE"), "{not_found:?}");
}
