//! `docs/tedris.md` lists every configuration key, and only real ones.

use deadreckon_tedris::TedrisConfig;

#[test]
fn docs_list_every_config_key() {
    let docs =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/tedris.md"))
            .expect("docs/tedris.md");
    let value = serde_json::to_value(TedrisConfig::default()).expect("serialises");
    let keys: Vec<&String> = value.as_object().expect("an object").keys().collect();
    assert!(keys.len() > 30, "{keys:?}");
    for k in &keys {
        assert!(
            docs.contains(&format!("| `{k}` |")),
            "docs/tedris.md does not document `{k}`"
        );
    }
    // Every documented key exists.
    for line in docs.lines().filter(|l| l.starts_with("| `")) {
        let key = line
            .trim_start_matches("| `")
            .split('`')
            .next()
            .unwrap_or("");
        assert!(
            keys.iter().any(|k| k.as_str() == key),
            "docs/tedris.md documents `{key}`, which is not a key"
        );
    }
}
