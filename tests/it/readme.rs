//! The README's Controls table and the editor's `?` overlay list the same controls, in the
//! same order and words, so that neither can drift from the other.

use knotwork::app::{CONTROLS, NAVIGATION_HINT};

/// The rows of the table under `## Controls` in README.md: (input, action).
fn readme_controls() -> Vec<(String, String)> {
    let readme = include_str!("../../README.md");
    let section = readme
        .split("## Controls")
        .nth(1)
        .expect("README.md has a Controls section");
    section
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|row| {
            let cells: Vec<&str> = row.trim_matches('|').split(" | ").map(str::trim).collect();
            assert_eq!(cells.len(), 2, "{row}");
            (cells[0].to_owned(), cells[1].to_owned())
        })
        .collect()
}

#[test]
fn the_readme_controls_are_the_help_overlays() {
    let overlay: Vec<(String, String)> = CONTROLS
        .iter()
        .map(|&(input, action)| (input.to_owned(), action.to_owned()))
        .collect();
    assert_eq!(readme_controls(), overlay);
}

#[test]
fn the_navigation_hint_says_what_the_table_says() {
    let table = readme_controls();
    for (input, action) in [("right drag", "orbit"), ("wheel", "zoom"), ("F", "frame")] {
        assert!(
            table
                .iter()
                .any(|(i, a)| i.starts_with(input) && a.contains(action)),
            "the table has {input}: {action}"
        );
        assert!(
            NAVIGATION_HINT.contains(&format!("{input}: {action}")),
            "the hint has {input}: {action}"
        );
    }
}
