// The guide's glossary (docs/guide.md, "### Glossary"), for the tests that keep it complete:
// `tests/glossary.rs` (the terms the command line prints on the example fixtures) and
// `src/gantt.rs` (every schedule source); the first includes it by `#[path]`, the second by `include!`.

/// The text of the glossary section of docs/guide.md, from its heading to the next heading
/// of the same or a higher level.
pub(crate) fn glossary() -> String {
    let guide = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/guide.md");
    let text = std::fs::read_to_string(guide).expect("docs/guide.md is readable");
    let start = text.find("### Glossary").expect("a `### Glossary` section");
    let rest = &text[start + 3..];
    let end = ["\n## ", "\n### "]
        .iter()
        .filter_map(|h| rest.find(h))
        .min()
        .unwrap_or(rest.len());
    rest[..end].to_owned()
}
