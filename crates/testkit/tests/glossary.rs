//! The glossary of docs/architecture.md held to the code: each word it lists has one meaning
//! (issue 58, item 4). A type the glossary names (`Path::Type`) is defined once in the
//! production sources, and the words that once meant several things mean one: one `Summary`,
//! no `Description` type (the crate is the description), one `Layout`, the `plan` modules the
//! glossary names and no other.

use specconv_testkit::sources::{production, root, sources};
use std::collections::BTreeMap;

/// Every type defined in production code (`struct`/`enum`/`type`/`trait` NAME): name → files.
fn definitions() -> BTreeMap<String, Vec<String>> {
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for file in sources() {
        let text = std::fs::read_to_string(root().join(&file)).unwrap();
        for line in production(&text) {
            let words: Vec<&str> = line.split_whitespace().collect();
            let at = words
                .iter()
                .position(|w| ["struct", "enum", "trait", "type"].contains(w));
            let Some(name) = at.and_then(|i| words.get(i + 1)) else {
                continue;
            };
            let name: String = name
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if name.chars().next().is_some_and(char::is_uppercase) {
                out.entry(name).or_default().push(file.clone());
            }
        }
    }
    out
}

/// The glossary's rows: (word, where).
fn glossary() -> Vec<(String, String)> {
    let doc = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let table = doc
        .split("## Glossary")
        .nth(1)
        .expect("docs/architecture.md has a Glossary section");
    table
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| word"))
        .map(|l| {
            let cells: Vec<&str> = l.split(" | ").collect();
            (
                cells[0].trim_start_matches("| ").to_string(),
                cells.last().unwrap().trim_end_matches(" |").to_string(),
            )
        })
        .collect()
}

#[test]
fn each_type_the_glossary_names_is_defined_once() {
    let defined = definitions();
    let mut checked = 0;
    for (word, place) in glossary() {
        for quoted in place.split('`').skip(1).step_by(2) {
            let last = quoted.rsplit("::").next().unwrap();
            let last = last.split_whitespace().last().unwrap_or(last);
            if !quoted.contains("::") || !last.chars().next().is_some_and(char::is_uppercase) {
                continue;
            }
            let files = defined.get(last).cloned().unwrap_or_default();
            assert_eq!(files.len(), 1, "{word}: `{last}` is defined in {files:?}");
            checked += 1;
        }
    }
    assert!(checked >= 6, "{checked} types checked");
}

#[test]
fn the_words_that_meant_several_things_mean_one() {
    let defined = definitions();
    let count = |name: &str| defined.get(name).map_or(0, Vec::len);
    assert_eq!(count("Summary"), 1, "Summary: {:?}", defined.get("Summary"));
    assert_eq!(count("Description"), 0, "{:?}", defined.get("Description"));
    assert_eq!(count("Layout"), 1, "Layout: {:?}", defined.get("Layout"));
    let mut plans: Vec<String> = sources()
        .into_iter()
        .filter(|f| f.ends_with("/plan.rs") || f.ends_with("/plan/mod.rs"))
        .collect();
    plans.sort();
    assert_eq!(
        plans,
        [
            "crates/asset/src/plan.rs",
            "crates/atomic-file/src/plan.rs",
            "crates/conversion/src/plan.rs"
        ],
        "the plan modules the glossary names"
    );
    for gone in ["crates/study", "crates/pictures"] {
        assert!(
            !root().join(gone).exists(),
            "{gone} is named for what it holds now"
        );
    }
}
