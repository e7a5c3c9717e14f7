//! Each thesis default is written once (issue 13): the literal appears in the code of exactly
//! one source file of the workspace and of the Python package; every other user takes it from
//! there (`ActuatorConstants::THESIS`, `RodCrank::THESIS`, the schema defaults).

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every file below `dir` ending in `ext`, skipping test, bench and fuzz trees.
fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("a readable source tree") {
        let path = entry.expect("a directory entry").path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if path.is_dir() {
            if !matches!(name, "tests" | "benches" | "fuzz" | "target" | "trials") {
                files(&path, ext, out);
            }
        } else if name.ends_with(ext) {
            out.push(path);
        }
    }
}

/// The code of a line: without a `//` or `#` comment (docs mention the thesis values).
fn code(line: &str, comment: &str) -> String {
    let line = line.split(comment).next().unwrap_or("");
    if comment == "#" && line.trim_start().starts_with(['"', '`']) {
        return String::new(); // docstring text in Python
    }
    line.to_string()
}

/// Whether `line` holds `needle`; a number only as a whole literal (`467`, not `46732.0`).
fn has(line: &str, needle: &str) -> bool {
    let number = |c: char| c.is_ascii_digit() || c == '.';
    line.match_indices(needle).any(|(i, _)| {
        let before = line[..i].chars().next_back();
        let after = line[i + needle.len()..].chars().next();
        !needle.starts_with(|c: char| c.is_ascii_digit())
            || !(before.is_some_and(number) || after.is_some_and(|c| c.is_ascii_digit()))
    })
}

/// The files (relative to the root) whose code has a line containing every `needle`.
fn written_in(needles: &[&str]) -> Vec<String> {
    let root = root();
    let mut paths = Vec::new();
    files(&root.join("crates"), ".rs", &mut paths);
    files(&root.join("python/paritysim"), ".py", &mut paths);
    let mut hits: Vec<String> = paths
        .iter()
        .filter(|p| {
            let comment = if p.extension().is_some_and(|e| e == "py") {
                "#"
            } else {
                "//"
            };
            let text = std::fs::read_to_string(p).expect("a readable source file");
            let in_tests = text.find("#[cfg(test)]").unwrap_or(text.len());
            text[..in_tests]
                .lines()
                .map(|l| code(l, comment))
                .any(|l| needles.iter().all(|n| has(&l, n)))
        })
        .map(|p| p.strip_prefix(&root).unwrap_or(p).display().to_string())
        .collect();
    hits.sort();
    hits
}

#[test]
fn the_thesis_actuator_constants_are_written_once() {
    assert_eq!(written_in(&["467"]), ["crates/laminate/src/bimorph.rs"]);
    assert_eq!(
        written_in(&["force_per_volt", "1.2"]),
        ["crates/laminate/src/bimorph.rs"]
    );
}

#[test]
fn the_thesis_linkage_lengths_are_written_once() {
    assert_eq!(
        written_in(&["crank", "0.4"]),
        ["crates/kinematics/src/drivetrain.rs"]
    );
    assert_eq!(
        written_in(&["rod", "0.8"]),
        ["crates/kinematics/src/drivetrain.rs"]
    );
    assert_eq!(
        written_in(&["WHIPPLETREE", "5.0"]),
        ["crates/kinematics/src/drivetrain.rs"]
    );
}

#[test]
fn the_default_aero_model_is_named_in_rust_only() {
    assert!(
        written_in(&["= \"dickinson1999\""]).is_empty(),
        "a Python default repeats the core's CoefficientSet::default()"
    );
}
