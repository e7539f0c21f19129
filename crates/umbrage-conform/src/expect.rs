//! Expected results, as Mesa's CI keeps them per driver (`lvp-fails.txt`): a checked-in list
//! of the cases a driver is known to fail, crash on, time out on or skip, one `case,Status` a
//! line (`#` comments). A `*` in a name matches any run of characters (dEQP's case pattern),
//! and an exact name wins over a pattern. A run judged against it fails on any *change*: a new
//! failure, crash or timeout, an expected one that now passes (the list must then shrink), and,
//! when the list has `Skip` lines, a case that skips unlisted (a pass that became a skip) or a
//! listed skip that now runs.

use super::suite::Report;
use super::Status;
use std::collections::BTreeMap;
use std::path::Path;
use umbrage::error::{Error, Result};

/// One driver's expected results: case name (or `*` pattern) -> the status it is expected to
/// end with. A case not listed is expected to pass.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Expectations {
    /// `Fail`, `Crash`, `Timeout` or `Skipped` per listed case or pattern.
    pub cases: BTreeMap<String, Status>,
}

/// How a run compares with its [`Expectations`].
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Verdict {
    /// Cases that failed, crashed or timed out without being listed (or with another status
    /// than listed).
    pub new_failures: Vec<String>,
    /// Listed cases that ran and passed.
    pub unexpected_passes: Vec<String>,
    /// Listed cases that failed as listed.
    pub expected_failures: usize,
    /// Cases that skipped without a `Skip` line (empty when the list has none: skips are then
    /// not judged).
    pub new_skips: Vec<String>,
    /// Cases listed as `Skip` that skipped.
    pub expected_skips: usize,
    /// Whether the run matched the list exactly ([`Verdict::ok`]).
    pub ok: bool,
}

impl Verdict {
    /// Whether the run matched its expectations exactly.
    pub fn ok(&self) -> bool {
        self.new_failures.is_empty() && self.unexpected_passes.is_empty() && self.new_skips.is_empty()
    }
}

impl Expectations {
    /// Parses the list format (`name,Fail` / `name,Crash` / `name,Timeout` / `name,Skip`,
    /// blank lines and `#` comments).
    pub fn parse(text: &str) -> Result<Expectations> {
        let mut cases = BTreeMap::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let (name, status) = line.rsplit_once(',').ok_or_else(|| {
                Error::input(format!("expectations line {}", i + 1), format!("expected `case,Status` (e.g. `case,Fail`), got '{line}'"))
            })?;
            let status = match status.trim() {
                "Fail" => Status::Fail,
                "Crash" => Status::Crash,
                "Timeout" => Status::Timeout,
                "Skip" => Status::Skipped,
                other => {
                    return Err(Error::input(
                        format!("expectations line {}", i + 1),
                        format!("unknown status '{other}' (Fail, Crash, Timeout or Skip)"),
                    ));
                }
            };
            if cases.insert(name.trim().to_string(), status).is_some() {
                return Err(Error::input(format!("expectations line {}", i + 1), format!("'{}' listed twice", name.trim())));
            }
        }
        Ok(Expectations { cases })
    }

    /// Reads and parses `path`.
    pub fn load(path: &Path) -> Result<Expectations> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path.display().to_string(), e))?;
        Self::parse(&text).map_err(|e| Error::input(path.display().to_string(), e.to_string()))
    }

    /// The status listed for `name`: its own line, else the first pattern (in name order) that
    /// matches it; `None` when it is expected to pass.
    pub fn listed(&self, name: &str) -> Option<Status> {
        if let Some(s) = self.cases.get(name) {
            return Some(*s);
        }
        self.cases.iter().find(|(p, _)| p.contains('*') && crate::deqp::names::glob(p, name)).map(|(_, s)| *s)
    }

    /// Whether the list pins skips (has a `Skip` line): only then is a skip judged.
    pub fn pins_skips(&self) -> bool {
        self.cases.values().any(|s| *s == Status::Skipped)
    }

    /// The list a run would need, in the file format: every failed, crashed and timed-out case
    /// of `r` by name, then its skips grouped by reason (a `#` line each), a whole group of
    /// names (`prefix.*`) where every case of `all` under that prefix skipped for that reason.
    /// `all` is the suite's every name (`suite::all_names`); pass `&[]` to list each skip.
    pub fn from_report(r: &Report, all: &[String]) -> String {
        let mut out: String = r
            .cases
            .iter()
            .filter_map(|c| match c.status {
                Status::Fail => Some(format!("{},Fail\n", c.name)),
                Status::Crash => Some(format!("{},Crash\n", c.name)),
                Status::Timeout => Some(format!("{},Timeout\n", c.name)),
                _ => None,
            })
            .collect();
        let mut by_reason: BTreeMap<String, Vec<&str>> = BTreeMap::new();
        for c in r.cases.iter().filter(|c| c.status == Status::Skipped) {
            by_reason.entry(one_line(&c.message)).or_default().push(&c.name);
        }
        for (reason, names) in &by_reason {
            out += &format!("\n# {reason}\n");
            for line in grouped(names, all) {
                out += &format!("{line},Skip\n");
            }
        }
        out
    }

    /// Compares `r` with the list. Listed cases that did not run (filtered out) count neither
    /// way; a skip counts only when the list pins skips ([`Expectations::pins_skips`]).
    pub fn judge(&self, r: &Report) -> Verdict {
        let pins_skips = self.pins_skips();
        let mut v = Verdict::default();
        for c in &r.cases {
            let listed = self.listed(&c.name);
            match (c.status, listed) {
                (Status::Fail | Status::Crash | Status::Timeout, Some(want)) if want == c.status => v.expected_failures += 1,
                (Status::Fail | Status::Crash | Status::Timeout, _) => v.new_failures.push(c.name.clone()),
                (Status::Pass, Some(_)) => v.unexpected_passes.push(c.name.clone()),
                (Status::Skipped, Some(Status::Skipped)) if pins_skips => v.expected_skips += 1,
                (Status::Skipped, _) if pins_skips => v.new_skips.push(c.name.clone()),
                _ => {}
            }
        }
        v.ok = v.ok();
        v
    }
}

/// `s` on one line (a skip's reason as a `#` comment).
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `names` as list lines: `prefix.*` for each shortest dot-prefix under which every name of
/// `all` is in `names` (two names at least), each other name as itself; sorted.
fn grouped(names: &[&str], all: &[String]) -> Vec<String> {
    use std::collections::{BTreeSet, HashMap};
    fn prefixes(name: &str) -> impl Iterator<Item = &str> {
        name.match_indices('.').map(move |(i, _)| &name[..i])
    }
    let mut total: HashMap<&str, usize> = HashMap::new();
    for n in all {
        for p in prefixes(n) {
            *total.entry(p).or_default() += 1;
        }
    }
    let mut mine: HashMap<&str, usize> = HashMap::new();
    for n in names {
        for p in prefixes(n) {
            *mine.entry(p).or_default() += 1;
        }
    }
    let mut lines = BTreeSet::new();
    for n in names {
        let whole = prefixes(n).find(|p| mine[p] >= 2 && total.get(p) == Some(&mine[p]));
        lines.insert(match whole {
            Some(p) => format!("{p}.*"),
            None => n.to_string(),
        });
    }
    lines.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_mesa_style_list() {
        let e = Expectations::parse("# comment\n\nraster.a,Fail\n  zoo.b , Crash \n").unwrap();
        assert_eq!(e.cases.len(), 2);
        assert_eq!(e.cases["raster.a"], Status::Fail);
        assert_eq!(e.cases["zoo.b"], Status::Crash);
        assert!(Expectations::parse("raster.a").is_err());
        assert!(Expectations::parse("raster.a,Flake").is_err());
        assert!(Expectations::parse("a,Fail\na,Fail").is_err());
    }

    fn report(statuses: &[(&str, Status)]) -> Report {
        let device = umbrage::gpu::DeviceInfo {
            name: "d".into(),
            kind: "CPU".into(),
            driver: String::new(),
            driver_info: String::new(),
            api_version: "1.0.2".into(),
            vendor_id: 0,
            device_id: 0,
        };
        let cases = statuses
            .iter()
            .map(|&(n, st)| {
                let mut o = crate::suite::CaseOutcome::new(n.into(), "raster", None, String::new());
                o.status = st;
                o
            })
            .collect();
        Report {
            device,
            features: Default::default(),
            validation: true,
            subpixel_bits: 8,
            filter: Vec::new(),
            formats: Vec::new(),
            configs: Vec::new(),
            cases,
            legacy: Vec::new(),
            seconds: 0.0,
            children: 0,
        }
    }

    #[test]
    fn judges_changes_only() {
        let e = Expectations::parse("a,Fail\nb,Crash\nc,Fail\nnot_run,Fail\n").unwrap();
        // a and b fail as listed, c passes (unexpected), d fails (new), b2 crashes (new).
        let r = report(&[("a", Status::Fail), ("b", Status::Crash), ("c", Status::Pass), ("d", Status::Fail), ("e", Status::Skipped)]);
        let v = e.judge(&r);
        assert_eq!(v.expected_failures, 2);
        assert_eq!(v.unexpected_passes, vec!["c".to_string()]);
        assert_eq!(v.new_failures, vec!["d".to_string()]);
        assert!(!v.ok());
        // A listed Fail that crashes is a change too.
        let v = e.judge(&report(&[("a", Status::Crash)]));
        assert_eq!(v.new_failures, vec!["a".to_string()]);
        // The list a run needs reproduces it exactly.
        let r = report(&[("a", Status::Fail), ("x", Status::Crash), ("y", Status::Pass)]);
        let again = Expectations::parse(&Expectations::from_report(&r, &[])).unwrap();
        assert!(again.judge(&r).ok());
    }

    fn skipped(name: &str, why: &str) -> crate::suite::CaseOutcome {
        let mut o = crate::suite::CaseOutcome::new(name.into(), "raster", None, String::new());
        o.status = Status::Skipped;
        o.message = why.into();
        o
    }

    #[test]
    fn pins_skips_when_the_list_has_them() {
        // Without a Skip line, skips are not judged (lists written before skips were pinned).
        let r = report(&[("a", Status::Pass), ("s", Status::Skipped)]);
        assert!(Expectations::parse("").unwrap().judge(&r).ok());
        // With one, a pass that became a skip fails, and so does a listed skip that now passes.
        let e = Expectations::parse("s,Skip\n").unwrap();
        let v = e.judge(&r);
        assert!(v.ok && v.expected_skips == 1, "{v:?}");
        let v = e.judge(&report(&[("a", Status::Skipped), ("s", Status::Skipped)]));
        assert_eq!(v.new_skips, vec!["a".to_string()]);
        assert!(!v.ok());
        let v = e.judge(&report(&[("a", Status::Pass), ("s", Status::Pass)]));
        assert_eq!(v.unexpected_passes, vec!["s".to_string()]);
        // A listed failure that skips is a change too.
        let e = Expectations::parse("f,Fail\ns,Skip\n").unwrap();
        assert_eq!(e.judge(&report(&[("f", Status::Skipped)])).new_skips, vec!["f".to_string()]);
        assert!(Expectations::parse("a,Skipped").is_err());
    }

    #[test]
    fn patterns_match_and_exact_names_win() {
        let e = Expectations::parse("x.y.*,Skip\nx.y.bad,Fail\n").unwrap();
        assert_eq!(e.listed("x.y.z"), Some(Status::Skipped));
        assert_eq!(e.listed("x.y.bad"), Some(Status::Fail));
        assert_eq!(e.listed("x.yz"), None);
        assert_eq!(e.listed("w.x.y.z"), None);
    }

    #[test]
    fn skips_are_written_grouped_by_reason_and_prefix() {
        let all: Vec<String> = ["a.p.1", "a.p.2", "a.q.1", "a.q.2", "b.1", "b.2", "c.1"].iter().map(|s| s.to_string()).collect();
        let mut r = report(&[("a.q.2", Status::Fail), ("b.2", Status::Pass), ("c.1", Status::Pass)]);
        r.cases.push(skipped("a.p.1", "no   depth\nbounds"));
        r.cases.push(skipped("a.p.2", "no depth bounds"));
        r.cases.push(skipped("a.q.1", "no depth bounds"));
        r.cases.push(skipped("b.1", "no mesh"));
        let text = Expectations::from_report(&r, &all);
        assert_eq!(text, "a.q.2,Fail\n\n# no depth bounds\na.p.*,Skip\na.q.1,Skip\n\n# no mesh\nb.1,Skip\n", "{text}");
        // Reading it back reproduces the run exactly.
        assert!(Expectations::parse(&text).unwrap().judge(&r).ok());
    }
}
