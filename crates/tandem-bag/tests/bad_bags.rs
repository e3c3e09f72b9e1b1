//! Every bad bag of the catalogue (`support/bad.rs`) is refused with an error naming the
//! file, the topic and, for a bad message, its index; the good bag it is made from reads.

use tandem_bag as bag;

#[path = "support/bad.rs"]
mod bad;

use bag::{BagOptions, read_bag};

#[test]
fn every_bad_bag_is_refused_naming_file_topic_and_message() {
    let dir = std::env::temp_dir().join(format!("tandem-bag-bad-{}", std::process::id()));
    let cases = bad::catalogue(&dir);
    assert!(cases.len() >= 20, "{} cases", cases.len());
    let good = read_bag(dir.join("good.mcap"), &BagOptions::default()).unwrap();
    assert_eq!(good.n_samples(), 101);
    for case in &cases {
        let options = BagOptions {
            topics: case.topics.clone(),
            ..BagOptions::default()
        };
        let err = match read_bag(&case.path, &options) {
            Ok(r) => panic!("{}: read {} samples", case.name, r.n_samples()),
            Err(e) => e.to_string(),
        };
        let file = case.path.display().to_string();
        assert!(
            err.starts_with(&file),
            "{}: `{err}` does not name {file}",
            case.name
        );
        for needle in &case.needles {
            assert!(
                err.contains(needle),
                "{}: `{err}` lacks `{needle}`",
                case.name
            );
        }
        // inspect refuses the same bags (those without a selection; a late start and a
        // channel clash are between topics, which inspect shows side by side rather than
        // refuses).
        let between_topics = ["late start", "two topics give one channel"];
        if case.topics.is_none() && !between_topics.contains(&case.name) {
            assert!(
                bag::inspect(&case.path).is_err(),
                "{}: inspect accepted it",
                case.name
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unsupported_topic_is_skipped_unless_selected() {
    let dir = std::env::temp_dir().join(format!("tandem-bag-skip-{}", std::process::id()));
    let cases = bad::catalogue(&dir);
    let unknown = cases.iter().find(|c| c.name == "unknown schema").unwrap();
    let rec = read_bag(&unknown.path, &BagOptions::default()).unwrap();
    assert_eq!(rec.channel_names[0], "pose.x");
    assert_eq!(rec.topics.len(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}
