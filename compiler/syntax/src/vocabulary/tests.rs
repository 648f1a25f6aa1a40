use super::*;

#[test]
fn every_child_key_exists_and_tags_are_unique_per_parent() {
    for e in ELEMENTS {
        let mut tags = Vec::new();
        for k in e.children {
            let child = spec(k);
            assert!(
                !tags.contains(&child.tag),
                "{} has two children tagged {}",
                e.key,
                child.tag
            );
            tags.push(child.tag);
        }
    }
}

#[test]
fn identifiers() {
    assert!(is_identifier("laser_2"));
    assert!(is_identifier("_x"));
    assert!(!is_identifier("2x"));
    assert!(!is_identifier("a-b"));
    assert!(!is_identifier(""));
    assert!(!is_identifier("ü"));
}
