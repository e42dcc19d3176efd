//! docs/columns.md carries the schema tables of `hd_model::schema` verbatim: each section
//! between `<!-- schema:NAME -->` and `<!-- /schema -->` must equal what the schema
//! generates. Run with `HDW_WRITE_DOCS=1` to rewrite the sections after a schema change.

use std::path::PathBuf;

#[test]
fn columns_md_matches_the_schema() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/columns.md");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut out = text.clone();
    let mut stale = Vec::new();
    for (name, table) in hd_model::schema::doc_sections() {
        let open = format!("<!-- schema:{name} -->\n");
        let start =
            out.find(&open).unwrap_or_else(|| panic!("docs/columns.md lacks {open}")) + open.len();
        let end = start + out[start..].find("<!-- /schema -->").expect("closing marker");
        if out[start..end] != table {
            stale.push(name);
            out.replace_range(start..end, &table);
        }
    }
    if std::env::var_os("HDW_WRITE_DOCS").is_some() {
        std::fs::write(&path, out).unwrap();
    } else {
        assert!(
            stale.is_empty(),
            "docs/columns.md is out of date in {stale:?}: run HDW_WRITE_DOCS=1 cargo test -p hd-model --test columns_doc"
        );
    }
}
