//! Tests of the key paths and the document edits of `--set`, `--sweep` and `--zip`.

use super::*;
use toml_edit::{DocumentMut, Value};

const DOC: &str = r#"# a scenario
duration = 120.0   # seconds
behaviour = { type = "wander", speed = 0.5 }

[[robots]]
name = "r1"
[[robots.localization]]
type = "mcl"
alpha = [0.1, 0.2]

[[robots]]
name = "r2"
"#;

fn set(key: &str, value: &str) -> anyhow::Result<(String, String)> {
    let mut doc: DocumentMut = DOC.parse().unwrap();
    let at = Override::new("--set", key, value)?.apply(&mut doc)?;
    Ok((at, doc.to_string()))
}

#[test]
fn paths() {
    assert_eq!(
        parse_path("--set", "robots[name=r1].localization.0").unwrap(),
        vec![
            Step::Key("robots".into()),
            Step::Select {
                key: "name".into(),
                value: "r1".into()
            },
            Step::Key("localization".into()),
            Step::Key("0".into()),
        ]
    );
    assert_eq!(
        parse_path("--set", "a[2][3]").unwrap(),
        vec![Step::Key("a".into()), Step::Index(2), Step::Index(3)]
    );
    for bad in ["a..b", "a.b c", "a[x", "[0]", "a[x y]"] {
        let e = parse_path("--set", bad).unwrap_err().to_string();
        assert!(e.starts_with(&format!("--set {bad}: ")), "{e}");
    }
}

#[test]
fn values() {
    assert!(matches!(parse_value("30"), Value::Integer(_)));
    assert!(matches!(parse_value("0.5"), Value::Float(_)));
    assert!(matches!(parse_value("[1, 2]"), Value::Array(_)));
    assert!(matches!(
        parse_value("{ type = \"rbpf\" }"),
        Value::InlineTable(_)
    ));
    assert_eq!(parse_value("pose").as_str(), Some("pose"));
    assert_eq!(parse_value("\"pose\"").as_str(), Some("pose"));
}

#[test]
fn applies_in_place() {
    let (at, text) = set("duration", "30").unwrap();
    assert_eq!(at, "duration");
    assert!(text.contains("duration = 30   # seconds"), "{text}");
    let (at, text) = set("robots[name=r2].speed", "0.7").unwrap();
    assert_eq!(at, "robots[1].speed");
    assert!(text.contains("name = \"r2\"\nspeed = 0.7"), "{text}");
    let (at, text) = set("robots.0.localization.0.alpha.1", "0.3").unwrap();
    assert_eq!(at, "robots[0].localization[0].alpha[1]");
    assert!(text.contains("alpha = [0.1, 0.3]"), "{text}");
    let (_, text) = set("behaviour.speed", "0.9").unwrap();
    assert!(text.contains("speed = 0.9 }"), "{text}");
    // missing tables are created inline, then filled
    let (at, text) = set("robots.0.sensors.laser.rate", "5").unwrap();
    assert_eq!(at, "robots[0].sensors.laser.rate");
    assert!(
        text.contains("sensors = { laser = { rate = 5 } }"),
        "{text}"
    );
    let text: String = {
        let mut doc: DocumentMut = DOC.parse().unwrap();
        for (k, v) in [
            ("robots.1.slam", "{ type = \"rbpf\" }"),
            ("robots.1.slam.particles", "15"),
        ] {
            Override::new("--set", k, v)
                .unwrap()
                .apply(&mut doc)
                .unwrap();
        }
        doc.to_string()
    };
    let slam: toml_edit::DocumentMut = text.parse().unwrap();
    let slam = &slam["robots"][1]["slam"];
    assert_eq!(slam["type"].as_str(), Some("rbpf"), "{text}");
    assert_eq!(slam["particles"].as_integer(), Some(15), "{text}");
}

#[test]
fn an_index_one_past_the_end_adds_an_item() {
    // a whole localizer as a table, then a key of a new robot, then an inline-array value
    let mut doc: DocumentMut = DOC.parse().unwrap();
    for (k, v) in [
        (
            "robots.0.localization.1",
            "{ type = \"de_mc\", init = \"global\" }",
        ),
        ("robots[2].name", "r3"),
        ("robots.0.localization.0.alpha.2", "0.3"),
    ] {
        Override::new("--set", k, v)
            .unwrap()
            .apply(&mut doc)
            .unwrap();
    }
    let text = doc.to_string();
    let doc: DocumentMut = text.parse().unwrap();
    let l = &doc["robots"][0]["localization"];
    assert_eq!(l[0]["type"].as_str(), Some("mcl"), "{text}");
    assert_eq!(l[1]["type"].as_str(), Some("de_mc"), "{text}");
    assert_eq!(l[1]["init"].as_str(), Some("global"), "{text}");
    assert_eq!(l[0]["alpha"].as_array().map(|a| a.len()), Some(3), "{text}");
    assert_eq!(doc["robots"][2]["name"].as_str(), Some("r3"), "{text}");
}

#[test]
fn structural_errors() {
    for (k, want) in [
        (
            "robots.5.name",
            "`robots` has 2 items: index 5 is out of range",
        ),
        (
            "robots[name=r9].x",
            "no item with name = r9 (its items' name: r1, r2)",
        ),
        ("robots.speed", "`robots` is an array: select an item"),
        ("duration.x", "`duration` is a number, not a table"),
        ("robots.0", "is a whole table"),
        (
            "robots.2",
            "adds an item to an array of tables: give a table",
        ),
        ("robots.0.localization.0.alpha.3", "index 3 is out of range"),
    ] {
        let e = set(k, "1").unwrap_err().to_string();
        assert!(e.starts_with(&format!("--set {k}=1: ")), "{e}");
        assert!(e.contains(want), "{k}: {e}");
    }
}

/// A value of kilobytes is shown shortened in the error, which still names the key.
#[test]
fn a_long_value_is_shortened_in_messages() {
    let long = "x".repeat(5000);
    let e = set("robots.5.name", &long).unwrap_err().to_string();
    assert!(e.starts_with("--set robots.5.name=xxxx"), "{e}");
    assert!(e.contains("…: `robots` has 2 items"), "{e}");
    assert!(e.len() < 300, "{} bytes: {e}", e.len());
    // short ones stay whole
    let o = Override::new("--set", "duration", "12").unwrap();
    assert_eq!(o.describe(), "--set duration=12");
}

#[test]
fn the_top_level_seed_is_told_apart() {
    let o = |k: &str| Override::new("--set", k, "1").unwrap();
    assert!(o("seed").is_seed());
    assert!(!o("robots.0.seed").is_seed() && !o("duration").is_seed());
}

#[test]
fn blames_the_override_on_the_error_path() {
    let o = |k: &str| Override::new("--sweep", k, "1").unwrap();
    let list = vec![
        (o("duration"), "duration".to_string()),
        (
            o("robots.0.slam.particles"),
            "robots[0].slam.particles".into(),
        ),
    ];
    let keys = |k: &str| -> Vec<String> { blame(&list, k).iter().map(|o| o.key.clone()).collect() };
    assert_eq!(keys("robots[0].slam"), ["robots.0.slam.particles"]);
    assert_eq!(keys("duration"), ["duration"]);
    assert!(keys("dt").is_empty());
    assert!(keys("robots[0].slam_x").is_empty());
}

#[test]
fn a_key_deeper_than_any_scenario_is_refused_before_it_is_applied() {
    // 20 000 levels overflowed the stack when the override was applied
    let deep = vec!["a"; 20_000].join(".");
    let e = set(&deep, "1").unwrap_err().to_string();
    assert!(
        e.contains("20000 parts, more than any scenario key has (at most 32)"),
        "{e}"
    );
    assert!(e.len() < 400, "the key is shortened in the message: {e}");
    let brackets = format!("robots{}", "[0]".repeat(40));
    let e = set(&brackets, "1").unwrap_err().to_string();
    assert!(e.contains("41 parts"), "{e}");
    // as deep as allowed: applied (as new nested tables), no overflow
    let ok = vec!["a"; MAX_KEY_PARTS].join(".");
    set(&ok, "1").unwrap();
}
