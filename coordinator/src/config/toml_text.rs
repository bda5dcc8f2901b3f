//! Guards and edits on the config's TOML text before it is read into
//! sections: `--set KEY=VALUE` overrides, the nesting limit and long lines
//! cut in error messages. Knows no section.

use anyhow::{anyhow, bail, Result};

/// Applies one `KEY=VALUE` override to a TOML table. VALUE is read as TOML
/// (`128`, `true`, `[1, 2]`, `"Cu"`); anything that is not TOML is a string.
pub(super) fn apply_set(table: &mut toml::Table, set: &str) -> Result<()> {
    let (key, value) = set
        .split_once('=')
        .ok_or_else(|| anyhow!("--set {set}: expected KEY=VALUE"))?;
    let key = key.trim();
    let parsed: toml::Value = match format!("v = {}", value.trim()).parse::<toml::Table>() {
        Ok(mut t) => t
            .remove("v")
            .unwrap_or(toml::Value::String(value.to_string())),
        Err(_) => toml::Value::String(value.trim().to_string()),
    };
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        bail!("--set {set}: malformed key `{key}`");
    }
    let mut cur = table;
    for p in &parts[..parts.len() - 1] {
        let entry = cur
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        cur = entry
            .as_table_mut()
            .ok_or_else(|| anyhow!("--set {set}: `{p}` is not a table"))?;
    }
    cur.insert(parts[parts.len() - 1].to_string(), parsed);
    Ok(())
}

/// Longest line of an error message echoed whole: a parse error quotes the
/// offending line, and a 10 MB key made a 31 MB message (#20 item 7).
const MAX_ECHO: usize = 200;

/// `msg` with every line longer than [`MAX_ECHO`] characters cut.
pub(super) fn shorten(msg: &str) -> String {
    msg.lines()
        .map(|l| match l.char_indices().nth(MAX_ECHO) {
            Some((cut, _)) => format!(
                "{}… ({} more characters)",
                &l[..cut],
                l[cut..].chars().count()
            ),
            None => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Deepest nesting a config may use: the deepest key of ours is
/// `materials.NAME.isotropic.youngs_gpa`; the TOML parser gives up on deep
/// nesting with "recursion limit" and no line (#20 item 7).
const MAX_NESTING: usize = 16;

/// Refuses a line whose key or value nests deeper than [`MAX_NESTING`]
/// (dots of a dotted key, brackets and braces), naming the line.
pub(super) fn check_nesting(text: &str) -> Result<()> {
    for (i, line) in text.lines().enumerate() {
        let (mut depth, mut deepest, mut dots) = (0usize, 0usize, 0usize);
        let mut quote: Option<char> = None;
        let mut seen_eq = false;
        for c in line.chars() {
            match (quote, c) {
                (Some(q), c) if c == q => quote = None,
                (Some(_), _) => {}
                (None, '"' | '\'') => quote = Some(c),
                (None, '#') => break,
                (None, '=') => seen_eq = true,
                (None, '.') if !seen_eq => dots += 1,
                (None, '[' | '{') => {
                    depth += 1;
                    deepest = deepest.max(depth);
                }
                (None, ']' | '}') => depth = depth.saturating_sub(1),
                _ => {}
            }
        }
        if dots + deepest > MAX_NESTING {
            bail!(
                "line {}: keys and values nest {} levels deep; a config needs at most {MAX_NESTING}",
                i + 1,
                dots + deepest
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{err, BASE};
    use crate::config::Config;

    #[test]
    fn issue20_item7_long_lines_are_cut_and_deep_keys_named() {
        let key = "k".repeat(10_000_000);
        let e = err(&format!("{BASE}\n{key} = 1\n"), &[]);
        assert!(e.len() < 2_000, "{} characters", e.len());
        assert!(e.contains("more characters"), "{}", &e[..e.len().min(400)]);
        let deep = vec!["a"; 100].join(".");
        let e = err(&format!("{deep} = 1\n{BASE}"), &[]);
        assert!(e.contains("line 1") && e.contains("nest"), "{e}");
        let nested = format!("x = {}1{}\n", "[".repeat(100), "]".repeat(100));
        let e = err(&format!("{nested}{BASE}"), &[]);
        assert!(e.contains("line 1"), "{e}");
        // Our own deepest keys and quoted names with dots pass.
        let ok = format!(
            "{BASE}\n[materials.\"a.b.c.d.e.f.g.h.i.j.k.l.m.n.o.p.q.r\"]\nisotropic = {{ youngs_gpa = 100.0, poisson = 0.3 }}\n"
        );
        Config::parse(&ok, &[]).unwrap();
    }
}
