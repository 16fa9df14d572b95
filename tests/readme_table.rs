//! The claim tables of the book page the README links are the ones the committed snapshot of the quick suite generates
//! (`experiments::readme_table`): a hand edit of either fails here. Regenerate with
//! `cargo run --release -p experiments --example readme_table -- readme`.

use experiments::readme_table::{current, table, Snapshot, SNAPSHOT, TABLE_FILE};

#[test]
fn readme_claims_table_is_generated_from_the_snapshot() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let snap: Snapshot =
        serde_json::from_str(&std::fs::read_to_string(format!("{root}/{SNAPSHOT}")).expect("snapshot"))
            .expect("parses");
    assert!(!snap.experiments.is_empty());
    let readme = std::fs::read_to_string(format!("{root}/{TABLE_FILE}")).expect("claims table page");
    let ours = current(&readme).expect("README has the generated part");
    assert_eq!(ours, table(&snap).trim(), "{TABLE_FILE}'s claims table differs from {SNAPSHOT}: run `cargo run --release -p experiments --example readme_table -- readme`");
}
