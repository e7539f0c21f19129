//! Expected failures, as Mesa's CI keeps them per driver (`lvp-fails.txt`): a checked-in list
//! of the cases a driver is known to fail, one `case,Fail` or `case,Crash` a line (`#`
//! comments). A run judged against it fails on any *change*: a new failure or crash, or an
//! expected one that now passes (the list must then shrink).

use super::suite::Report;
use super::Status;
use std::collections::BTreeMap;
use std::path::Path;
use umbrage::error::{Error, Result};

/// One driver's expected failures: case name -> the status it is expected to end with.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Expectations {
    /// `Fail` or `Crash` per listed case.
    pub cases: BTreeMap<String, Status>,
}

/// How a run compares with its [`Expectations`].
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Verdict {
    /// Cases that failed or crashed without being listed (or with another status than listed).
    pub new_failures: Vec<String>,
    /// Listed cases that ran and passed.
    pub unexpected_passes: Vec<String>,
    /// Listed cases that failed as listed.
    pub expected_failures: usize,
}

impl Verdict {
    /// Whether the run matched its expectations exactly.
    pub fn ok(&self) -> bool {
        self.new_failures.is_empty() && self.unexpected_passes.is_empty()
    }
}

impl Expectations {
    /// Parses the list format (`name,Fail` / `name,Crash`, blank lines and `#` comments).
    pub fn parse(text: &str) -> Result<Expectations> {
        let mut cases = BTreeMap::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let (name, status) = line.rsplit_once(',').ok_or_else(|| {
                Error::input(format!("expectations line {}", i + 1), format!("expected `case,Fail` or `case,Crash`, got '{line}'"))
            })?;
            let status = match status.trim() {
                "Fail" => Status::Fail,
                "Crash" => Status::Crash,
                other => {
                    return Err(Error::input(format!("expectations line {}", i + 1), format!("unknown status '{other}' (Fail or Crash)")));
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

    /// The list a run would need: every failed or crashed case of `r`, in the file format.
    pub fn from_report(r: &Report) -> String {
        r.cases
            .iter()
            .filter_map(|c| match c.status {
                Status::Fail => Some(format!("{},Fail\n", c.name)),
                Status::Crash => Some(format!("{},Crash\n", c.name)),
                _ => None,
            })
            .collect()
    }

    /// Compares `r` with the list. Listed cases that did not run (filtered out or skipped) are
    /// neither new failures nor unexpected passes.
    pub fn judge(&self, r: &Report) -> Verdict {
        let mut v = Verdict::default();
        for c in &r.cases {
            let listed = self.cases.get(&c.name).copied();
            match (c.status, listed) {
                (Status::Fail | Status::Crash, Some(want)) if want == c.status => v.expected_failures += 1,
                (Status::Fail | Status::Crash, _) => v.new_failures.push(c.name.clone()),
                (Status::Pass, Some(_)) => v.unexpected_passes.push(c.name.clone()),
                _ => {}
            }
        }
        v
    }
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
        let again = Expectations::parse(&Expectations::from_report(&r)).unwrap();
        assert!(again.judge(&r).ok());
    }
}
