//! Checks of the figures that README.md and docs/*.md quote from runs: a
//! test runs the example, reads the figure from the document's text and
//! fails, naming the document's line, when they disagree (a stale figure).
//! Shared by the workspace tests (`tests/`) and the CLI's
//! (`crates/cli/tests/`, included by path), so that one rule reads them.
#![allow(dead_code)]

use std::path::PathBuf;

/// The repository's root (the folder holding README.md and Cargo.lock),
/// found upwards from the test's crate.
pub fn root() -> PathBuf {
    let mut dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    while !(dir.join("README.md").exists() && dir.join("Cargo.lock").exists()) {
        assert!(
            dir.pop(),
            "no README.md above {}",
            env!("CARGO_MANIFEST_DIR")
        );
    }
    dir
}

/// A document of the repository (`README.md`, `docs/sweep.md`, …).
pub struct Doc {
    pub name: String,
    text: String,
    /// The text with every run of white space as one space: a quoted
    /// phrase may wrap across lines.
    flat: String,
}

/// Reads `name` (relative to the repository's root).
pub fn doc(name: &str) -> Doc {
    let text = std::fs::read_to_string(root().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    Doc {
        name: name.to_owned(),
        flat: flatten(&text),
        text,
    }
}

/// `s` with every run of white space as one space (kept at its ends).
fn flatten(s: &str) -> String {
    let inner = s.split_whitespace().collect::<Vec<_>>().join(" ");
    let lead = if s.starts_with(char::is_whitespace) {
        " "
    } else {
        ""
    };
    let trail = if s.ends_with(char::is_whitespace) && !inner.is_empty() {
        " "
    } else {
        ""
    };
    format!("{lead}{inner}{trail}")
}

/// The characters a quoted number is made of (`1,898`, `-0.25`, `4e-21`).
fn numeric(c: char) -> bool {
    c.is_ascii_digit() || matches!(c, '.' | ',' | '-' | '−' | 'e' | '+')
}

impl Doc {
    /// The document's lines that contain the start of `phrase`, to show
    /// where a stale figure is.
    fn near(&self, phrase: &str) -> String {
        let key: String = flatten(phrase).chars().take(20).collect();
        let key = key.trim();
        let lines: Vec<&str> = self.text.lines().filter(|l| l.contains(key)).collect();
        if lines.is_empty() {
            format!("(no line of {} contains {key:?})", self.name)
        } else {
            lines.join("\n  ")
        }
    }

    /// Fails unless the document contains `want` (white space as any run
    /// of white space).
    pub fn has(&self, want: &str, what: &str) {
        if self.flat.contains(&flatten(want)) {
            return;
        }
        panic!(
            "{} is stale ({what}): expected\n  {want}\nits lines starting alike:\n  {}",
            self.name,
            self.near(want)
        );
    }

    /// The number quoted between `before` and `after` (each matched with
    /// white space as any run of white space; the number may contain
    /// thousands separators, a Unicode minus, an exponent): its text as
    /// written. Fails unless exactly one place of the document matches.
    pub fn quoted(&self, before: &str, after: &str) -> String {
        let (b, a) = (flatten(before), flatten(after));
        let mut found = Vec::new();
        let mut from = 0;
        while let Some(i) = self.flat[from..].find(&b) {
            let start = from + i + b.len();
            let rest = &self.flat[start..];
            let len: usize = rest
                .char_indices()
                .take_while(|&(_, c)| numeric(c))
                .map(|(_, c)| c.len_utf8())
                .sum();
            // A figure ends with a digit (not a sentence's full stop).
            let mut num = &rest[..len];
            while num.ends_with(['.', ',', '-', 'e', '+']) {
                num = &num[..num.len() - 1];
            }
            if !num.is_empty() && rest[num.len()..].starts_with(&a) {
                found.push(num.to_owned());
            }
            from = start;
        }
        match found.len() {
            1 => found.pop().unwrap(),
            0 => panic!(
                "{}: no figure quoted as `{before}N{after}`; its lines starting alike:\n  {}",
                self.name,
                self.near(before)
            ),
            _ => panic!(
                "{}: `{before}N{after}` is quoted {} times ({found:?}): make the phrase unique",
                self.name,
                found.len()
            ),
        }
    }

    /// Fails unless the figure quoted between `before` and `after` is
    /// `value` written with as many decimals as the document gives
    /// (`0.148` against 0.14815…): the document rounds what the run gives.
    pub fn figure(&self, before: &str, after: &str, value: f64, what: &str) {
        let q = self.quoted(before, after);
        let decimals = q.split_once('.').map_or(0, |(_, d)| {
            d.chars().take_while(char::is_ascii_digit).count()
        });
        let want = fixed(value, decimals);
        let got = q.replace(',', "").replace('−', "-");
        if got != want {
            panic!(
                "{} is stale ({what}): quotes `{before}{q}{after}`, the run gives {want} ({value})\n  {}",
                self.name,
                self.near(before)
            );
        }
    }

    /// Fails unless the integer quoted between `before` and `after` is `n`.
    pub fn count(&self, before: &str, after: &str, n: usize, what: &str) {
        let q = self.quoted(before, after);
        let got: usize = q
            .replace(',', "")
            .parse()
            .unwrap_or_else(|_| panic!("{}: `{before}{q}{after}` is not a count", self.name));
        if got != n {
            panic!(
                "{} is stale ({what}): quotes `{before}{q}{after}`, the run gives {n}\n  {}",
                self.name,
                self.near(before)
            );
        }
    }

    /// Fails unless the number quoted between `before` and `after`, read
    /// as written (`4e-21`, `0.195`), is `value` to one unit of its last
    /// quoted digit (`{:.0e}`-style mantissas too).
    pub fn approx(&self, before: &str, after: &str, value: f64, what: &str) {
        let q = self.quoted(before, after);
        let got: f64 = q
            .replace(',', "")
            .replace('−', "-")
            .parse()
            .unwrap_or_else(|_| panic!("{}: `{before}{q}{after}` is not a number", self.name));
        let unit = last_digit_unit(&q.replace(',', ""));
        if (got - value).abs() > 0.5 * unit * (1.0 + 1e-9) {
            panic!(
                "{} is stale ({what}): quotes `{before}{q}{after}`, the run gives {value}\n  {}",
                self.name,
                self.near(before)
            );
        }
    }

    /// The cells of the Markdown table row starting with `first` (the
    /// first cell's text), trimmed.
    pub fn row(&self, first: &str) -> Vec<String> {
        let prefix = format!("| {first} |");
        let rows: Vec<&str> = self
            .text
            .lines()
            .filter(|l| l.starts_with(&prefix))
            .collect();
        assert_eq!(
            rows.len(),
            1,
            "{}: expected one table row starting `{prefix}`, found {rows:?}",
            self.name
        );
        rows[0]
            .trim()
            .trim_matches('|')
            .split('|')
            .map(|c| c.trim().to_owned())
            .collect()
    }
}

/// The value of one unit of the last digit of a decimal or exponent
/// number as written: `0.195` → 0.001, `4e-21` → 1e-21, `13` → 1.
pub fn last_digit_unit(q: &str) -> f64 {
    let (mantissa, exp) = match q.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().unwrap_or(0)),
        None => (q, 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
    10f64.powi(exp - decimals)
}

/// `x` with `decimals` decimals, never `-0.000`.
pub fn fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_owned(),
        _ => s,
    }
}

/// Parses a quoted number (`1,898`, `−0.25`, `0.20 s` without its unit).
pub fn parse(q: &str) -> f64 {
    let t: String = q
        .trim()
        .chars()
        .take_while(|&c| numeric(c))
        .filter(|&c| c != ',')
        .map(|c| if c == '−' { '-' } else { c })
        .collect();
    t.parse()
        .unwrap_or_else(|_| panic!("`{q}` does not start with a number"))
}
