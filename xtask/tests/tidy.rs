//! Docs a test keeps true (issue 40, item 6).
//!
//! - docs/ARCHITECTURE.md, "Crates": one section per crate of the workspace (`crates/*` and
//!   `xtask`), each at most [`MAX_SECTION_CHARS`] characters, with its invariants in bold, an
//!   "Absent by design:" line and a "Modules:" line naming exactly the crate's top-level modules
//!   (`(pub)` marking the public ones). A module added, removed or made public without its
//!   paragraph fails here, naming the crate and the difference.
//! - docs/decisions.md, "Contents": every `## ` section listed exactly once, with a status that
//!   is "in force" or "replaced by" a section that exists, and no link to a missing heading.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The longest crate section of ARCHITECTURE.md, in characters (the old table's rows ran to
/// 3,400; a paragraph a reader takes in at once is well under this).
const MAX_SECTION_CHARS: usize = 2000;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace root")
        .to_path_buf()
}

fn read(path: &Path) -> String {
    fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// Every crate of the workspace: its name (the folder name) and folder.
fn crates() -> Vec<(String, PathBuf)> {
    let root = root();
    let mut out: Vec<(String, PathBuf)> = fs::read_dir(root.join("crates"))
        .expect("crates/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("Cargo.toml").is_file())
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), p))
        .collect();
    out.push(("xtask".into(), root.join("xtask")));
    out.sort();
    out
}

/// The crate's top-level modules: each `src/x.rs` and `src/x/` (but `lib.rs`, `main.rs`) and
/// each module declared inline in the crate root, mapped to whether the root declares it `pub`.
fn modules_of(dir: &Path) -> BTreeMap<String, bool> {
    let src = dir.join("src");
    let roots: Vec<String> = ["lib.rs", "main.rs"]
        .iter()
        .map(|f| src.join(f))
        .filter(|p| p.is_file())
        .map(|p| read(&p))
        .collect();
    let declared = |public: bool| -> BTreeSet<String> {
        let mut names = BTreeSet::new();
        for text in &roots {
            for line in text.lines() {
                let line = line.trim_start();
                let rest = if public {
                    line.strip_prefix("pub mod ")
                } else {
                    line.strip_prefix("mod ")
                };
                if let Some(rest) = rest {
                    let name: String = rest
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    if !name.is_empty() && name != "tests" {
                        names.insert(name);
                    }
                }
            }
        }
        names
    };
    let public = declared(true);
    let mut out = BTreeMap::new();
    for entry in fs::read_dir(&src).expect("src/ exists").flatten() {
        let path = entry.path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let module = if path.is_dir() {
            name
        } else if let Some(stem) = name.strip_suffix(".rs") {
            if stem == "lib" || stem == "main" {
                continue;
            }
            stem.to_string()
        } else {
            continue;
        };
        out.insert(module.clone(), public.contains(&module));
    }
    for name in public {
        out.entry(name).or_insert(true);
    }
    out
}

/// The crate sections of ARCHITECTURE.md's "## Crates": heading name → section text.
fn architecture_sections(text: &str) -> BTreeMap<String, String> {
    let start = text
        .find("\n## Crates\n")
        .expect("docs/ARCHITECTURE.md has a \"## Crates\" section");
    let body = &text[start + 1..];
    let body = &body[..body[3..].find("\n## ").map_or(body.len(), |i| i + 4)];
    let mut out = BTreeMap::new();
    let mut parts = body.split("\n### ").skip(1);
    for part in parts.by_ref() {
        let (heading, rest) = part.split_once('\n').unwrap_or((part, ""));
        let name = heading.trim().trim_matches('`').to_string();
        out.insert(name, rest.trim().to_string());
    }
    out
}

/// The names of a "Modules:" line, each mapped to whether it is marked `(pub)`.
fn listed_modules(section: &str) -> Option<BTreeMap<String, bool>> {
    let line = section.lines().find(|l| l.starts_with("Modules:"))?;
    let mut out = BTreeMap::new();
    let mut rest = line;
    while let Some(open) = rest.find('`') {
        let after = &rest[open + 1..];
        let close = after.find('`')?;
        let name = after[..close].trim_end_matches('/').to_string();
        rest = &after[close + 1..];
        let public = rest.trim_start().starts_with("(pub)");
        out.insert(name, public);
    }
    Some(out)
}

#[test]
fn architecture_has_one_true_section_per_crate() {
    let text = read(&root().join("docs/ARCHITECTURE.md"));
    let sections = architecture_sections(&text);
    let mut problems = Vec::new();
    let crates = crates();
    let names: BTreeSet<&str> = crates.iter().map(|(n, _)| n.as_str()).collect();
    for extra in sections.keys().filter(|k| !names.contains(k.as_str())) {
        problems.push(format!(
            "docs/ARCHITECTURE.md has a section `{extra}` but the workspace has no such crate: remove it"
        ));
    }
    for (name, dir) in &crates {
        let Some(section) = sections.get(name) else {
            problems.push(format!(
                "crate `{name}` has no section in docs/ARCHITECTURE.md, \"## Crates\": add `### `{name}`` with its purpose, invariants, what is absent by design and a Modules: line"
            ));
            continue;
        };
        let chars = section.chars().count();
        if chars > MAX_SECTION_CHARS {
            problems.push(format!(
                "the section of `{name}` has {chars} characters, more than {MAX_SECTION_CHARS}: say less (rustdoc holds the details)"
            ));
        }
        if !section.contains("**") {
            problems.push(format!(
                "the section of `{name}` states no invariant in bold"
            ));
        }
        if !section.contains("Absent by design:") {
            problems.push(format!(
                "the section of `{name}` has no \"Absent by design:\" line"
            ));
        }
        let Some(listed) = listed_modules(section) else {
            problems.push(format!("the section of `{name}` has no \"Modules:\" line"));
            continue;
        };
        let actual = modules_of(dir);
        for (module, public) in &actual {
            match listed.get(module) {
                None => problems.push(format!(
                    "`{name}` has the module `{module}`{} that its section's Modules: line does not name",
                    if *public { " (pub)" } else { "" }
                )),
                Some(p) if p != public => problems.push(format!(
                    "`{name}`'s module `{module}` is {}public but its Modules: line says {}",
                    if *public { "" } else { "not " },
                    if *p { "(pub)" } else { "private" }
                )),
                Some(_) => {}
            }
        }
        for module in listed.keys().filter(|m| !actual.contains_key(*m)) {
            problems.push(format!(
                "the Modules: line of `{name}` names `{module}`, which the crate does not have"
            ));
        }
    }
    assert!(
        problems.is_empty(),
        "docs/ARCHITECTURE.md is out of date:\n- {}",
        problems.join("\n- ")
    );
}

/// GitHub's anchor of a heading: lower case, letters, digits, `-` and `_` kept, spaces to `-`.
fn slug(heading: &str) -> String {
    heading
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// Every `(#anchor)` link target in a line.
fn anchors(line: &str) -> Vec<&str> {
    line.match_indices("](#")
        .filter_map(|(i, _)| {
            let rest = &line[i + 3..];
            rest.find(')').map(|j| &rest[..j])
        })
        .collect()
}

#[test]
fn decisions_are_indexed_with_a_status() {
    let text = read(&root().join("docs/decisions.md"));
    let headings: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("## "))
        .filter(|h| *h != "Contents")
        .collect();
    let slugs: BTreeSet<String> = headings.iter().map(|h| slug(h)).collect();
    assert_eq!(
        slugs.len(),
        headings.len(),
        "two sections of docs/decisions.md have the same heading"
    );
    let contents = text
        .split("\n## Contents\n")
        .nth(1)
        .expect("docs/decisions.md has a \"## Contents\" section");
    let contents = &contents[..contents.find("\n## ").unwrap_or(contents.len())];
    let mut problems = Vec::new();
    let mut listed: BTreeMap<String, usize> = BTreeMap::new();
    for row in contents
        .lines()
        .filter(|l| l.starts_with("| ") && l.contains("](#"))
    {
        let cells: Vec<&str> = row.split(" | ").collect();
        if cells.len() != 3 {
            problems.push(format!(
                "a contents row is not `| area | decision | status |`: {row}"
            ));
            continue;
        }
        let decision = anchors(cells[1]);
        let Some(&target) = decision.first() else {
            problems.push(format!("a contents row links no section: {row}"));
            continue;
        };
        *listed.entry(target.to_string()).or_default() += 1;
        let status = cells[2].trim_end_matches(" |").trim();
        if !(status.starts_with("in force") || status.starts_with("replaced by")) {
            problems.push(format!(
                "the status of #{target} is \"{status}\": it must be \"in force\" or \"replaced by [section](#anchor)\""
            ));
        }
        if status.starts_with("replaced by") && anchors(status).is_empty() {
            problems.push(format!("#{target} is replaced by nothing it links"));
        }
        for a in decision.iter().chain(anchors(status).iter()) {
            if !slugs.contains(*a) {
                problems.push(format!("the contents link to #{a}, which is no heading"));
            }
        }
    }
    for s in &slugs {
        match listed.get(s) {
            None => problems.push(format!(
                "the section #{s} is not in the contents: add a row with its area and status"
            )),
            Some(n) if *n > 1 => problems.push(format!("the section #{s} is listed {n} times")),
            Some(_) => {}
        }
    }
    assert!(
        problems.is_empty(),
        "docs/decisions.md's contents are out of date:\n- {}",
        problems.join("\n- ")
    );
}

#[test]
fn slugs_follow_github() {
    assert_eq!(
        slug("tandem-warp: smoothing before alignment (`smooth_width` = 7)"),
        "tandem-warp-smoothing-before-alignment-smooth_width--7"
    );
    assert_eq!(
        slug("The fixtures' transitions: 16 s ± 45 %"),
        "the-fixtures-transitions-16-s--45-"
    );
}
