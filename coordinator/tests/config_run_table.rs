//! The optional `[run]` table of the config (runner settings, not physics).

use coordinator::config::Config;

const BASE: &str = concat!(
    include_str!("../../tests/configs/table1c-coarse.toml"),
    "\n[sweep]\nmaterials = [\"Cu\"]\n"
);

fn err(text: &str) -> String {
    format!("{:#}", Config::parse(text, &[]).unwrap_err())
}

#[test]
fn run_table_sets_the_case_timeout_and_is_checked() {
    let c = Config::parse(BASE, &[]).unwrap();
    assert_eq!(c.run.case_timeout_s, 60.0);
    assert!(
        !c.to_toml().contains("[run]"),
        "default [run] is not echoed"
    );
    let c = Config::parse(&format!("{BASE}\n[run]\ncase_timeout_s = 5\n"), &[]).unwrap();
    assert_eq!(c.run.case_timeout_s, 5.0);
    assert!(c.to_toml().contains("case_timeout_s = 5"));
    let c = Config::parse(BASE, &["run.case_timeout_s=2.5".into()]).unwrap();
    assert_eq!(c.run.case_timeout_s, 2.5);
    for bad in [
        "case_timeout_s = 0",
        "case_timeout_s = -1",
        "case_timeout_s = nan",
    ] {
        let e = err(&format!("{BASE}\n[run]\n{bad}\n"));
        assert!(e.contains("run.case_timeout_s"), "{bad}: {e}");
    }
    let e = err(&format!("{BASE}\n[run]\ncase_timeout = 5\n"));
    assert!(e.contains("case_timeout"), "{e}");
    let e = err(&format!("{BASE}\n[run]\ncase_timeout_s = \"soon\"\n"));
    assert!(
        e.contains("case_timeout_s") || e.contains("invalid type"),
        "{e}"
    );
}
