//! Mesa's expectation files and deqp-runner's outputs, for `umbrage conform` run alone:
//! a baseline of `name,Status` lines (every status deqp-runner writes; a duplicate is an
//! error), flakes and skips files of regexes (one a line, `#` comments; a line without regex
//! syntax has its dots taken literally, as deqp-runner 0.24 does), the verdict of each case
//! against them ([`Judged`], deqp-runner's `RunnerStatus`), and `results.csv`
//! (`name,Status,seconds`) and `failures.csv` (`name,Status`: the next baseline).

use super::exec::Code;
use super::names;
use std::collections::HashMap;
use std::fmt;
use std::path::Path;
use umbrage::error::{Error, Result};

/// A case's verdict against the baseline and flakes (deqp-runner's names).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Judged {
    /// Passed, not listed as failing.
    Pass,
    /// Failed, not listed.
    Fail,
    /// Not supported by the device, or skipped by `--skips`.
    Skip,
    /// Crashed, not listed.
    Crash,
    /// Hung, not listed.
    Timeout,
    /// Its status changed when it was run again.
    Flake,
    /// An unexpected result of a case the flakes file names.
    KnownFlake,
    /// No result came back.
    Missing,
    /// Failed (crashed, hung) as the baseline lists it.
    ExpectedFail,
    /// Better than the baseline says: the status it had (remove or update its line).
    UnexpectedImprovement(Code),
}

impl Judged {
    /// Whether the run is fine with it (deqp-runner's `is_success`).
    pub fn is_success(self) -> bool {
        matches!(self, Judged::Pass | Judged::Skip | Judged::Flake | Judged::KnownFlake | Judged::ExpectedFail)
    }

    /// The raw result, without a baseline.
    pub fn raw(code: Code) -> Judged {
        match code {
            Code::Pass => Judged::Pass,
            Code::Fail => Judged::Fail,
            Code::NotSupported => Judged::Skip,
            Code::Crash => Judged::Crash,
            Code::Timeout => Judged::Timeout,
        }
    }

    /// `code` judged against the baseline's line for the case (deqp-runner's `with_baseline`).
    pub fn with_baseline(code: Code, baseline: Option<Judged>) -> Judged {
        use Judged::*;
        let raw = Judged::raw(code);
        let Some(b) = baseline else { return raw };
        match raw {
            Fail => match b {
                Fail | ExpectedFail => ExpectedFail,
                Crash | Timeout => UnexpectedImprovement(Code::Fail),
                _ => Fail,
            },
            Pass => match b {
                Fail | Crash | Missing | Timeout => UnexpectedImprovement(Code::Pass),
                _ => Pass,
            },
            Crash => match b {
                Crash | ExpectedFail => ExpectedFail,
                _ => Crash,
            },
            Skip => match b {
                Fail | Crash | Missing | Timeout => UnexpectedImprovement(Code::NotSupported),
                _ => Skip,
            },
            Timeout => match b {
                Timeout => ExpectedFail,
                _ => Timeout,
            },
            other => other,
        }
    }
}

impl fmt::Display for Judged {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Judged::Pass => f.write_str("Pass"),
            Judged::Fail => f.write_str("Fail"),
            Judged::Skip => f.write_str("Skip"),
            Judged::Crash => f.write_str("Crash"),
            Judged::Timeout => f.write_str("Timeout"),
            Judged::Flake => f.write_str("Flake"),
            Judged::KnownFlake => f.write_str("KnownFlake"),
            Judged::Missing => f.write_str("Missing"),
            Judged::ExpectedFail => f.write_str("ExpectedFail"),
            Judged::UnexpectedImprovement(c) => {
                let s = if *c == Code::NotSupported { "Skip" } else { c.name() };
                write!(f, "UnexpectedImprovement({s})")
            }
        }
    }
}

impl std::str::FromStr for Judged {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Judged, String> {
        if let Some(inner) = s.strip_prefix("UnexpectedImprovement(").and_then(|r| r.strip_suffix(')')) {
            let c = match inner {
                "Pass" => Code::Pass,
                "Fail" => Code::Fail,
                "Skip" => Code::NotSupported,
                "Crash" => Code::Crash,
                "Timeout" => Code::Timeout,
                _ => return Err(format!("unknown status '{s}'")),
            };
            return Ok(Judged::UnexpectedImprovement(c));
        }
        Ok(match s {
            "Pass" => Judged::Pass,
            "Fail" => Judged::Fail,
            "Skip" => Judged::Skip,
            "Crash" => Judged::Crash,
            "Timeout" => Judged::Timeout,
            "Flake" => Judged::Flake,
            "KnownFlake" => Judged::KnownFlake,
            "Warn" => Judged::Pass,
            "Missing" => Judged::Missing,
            "ExpectedFail" => Judged::ExpectedFail,
            _ => return Err(format!("unknown status '{s}' (Pass, Fail, Skip, Crash, Timeout, Flake, KnownFlake, Missing, ExpectedFail)")),
        })
    }
}

/// A baseline: public case name → the status it is expected to end with.
#[derive(Clone, Debug, Default)]
pub struct Baseline {
    /// The listed cases.
    pub cases: HashMap<String, Judged>,
}

impl Baseline {
    /// Parses `name,Status[,...]` lines (blank lines and `#` comments skipped). A short name
    /// (`stencil.…`) is taken as its public name.
    pub fn parse(text: &str) -> std::result::Result<Baseline, String> {
        let mut cases = HashMap::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let mut parts = line.split(',');
            let (Some(name), Some(status)) = (parts.next(), parts.next()) else {
                return Err(format!("line {}: expected `name,Status`, got '{line}'", i + 1));
            };
            let status: Judged = status.trim().parse().map_err(|e| format!("line {}: {e}", i + 1))?;
            let name = name.trim();
            let name = if name.starts_with(names::PREFIX) { name.to_string() } else { names::public(name) };
            if cases.insert(name.clone(), status).is_some() {
                return Err(format!("line {}: '{name}' listed twice", i + 1));
            }
        }
        Ok(Baseline { cases })
    }

    /// Reads and parses `path`.
    pub fn load(path: &Path) -> Result<Baseline> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path.display().to_string(), e))?;
        Self::parse(&text).map_err(|e| Error::input(path.display().to_string(), e.to_string()))
    }
}

/// A skips or flakes list: regexes, any of which matching (anywhere in the public name) selects.
#[derive(Clone, Debug, Default)]
pub struct Regexes {
    set: Option<regex::RegexSet>,
}

impl Regexes {
    /// Parses the lines of `texts` (deqp-runner's `parse_regex_set`).
    pub fn parse(texts: &[String]) -> std::result::Result<Regexes, String> {
        let mut lines = Vec::new();
        for line in texts.iter().flat_map(|t| t.lines()) {
            let t = line.trim();
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            if t.rsplit(',').next().is_some_and(|s| s.parse::<Judged>().is_ok()) {
                return Err(format!("regex line appears to contain a result status: {t}"));
            }
            let is_regex = t.chars().any(|c| "*+?()[]{}|^$\\".contains(c));
            lines.push(if is_regex { t.to_string() } else { t.replace('.', "\\.") });
        }
        if lines.is_empty() {
            return Ok(Regexes { set: None });
        }
        regex::RegexSet::new(&lines).map(|s| Regexes { set: Some(s) }).map_err(|e| e.to_string())
    }

    /// Reads and parses the files.
    pub fn load(paths: &[std::path::PathBuf]) -> Result<Regexes> {
        let mut texts = Vec::new();
        for p in paths {
            texts.push(std::fs::read_to_string(p).map_err(|e| Error::io(p.display().to_string(), e))?);
        }
        Self::parse(&texts)
            .map_err(|e| Error::input(paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "), e.to_string()))
    }

    /// Whether any regex matches `name`.
    pub fn is_match(&self, name: &str) -> bool {
        self.set.as_ref().is_some_and(|s| s.is_match(name))
    }
}

/// One case's line of `results.csv`.
#[derive(Clone, Debug)]
pub struct Row {
    /// Public name.
    pub name: String,
    /// Verdict.
    pub status: Judged,
    /// Seconds.
    pub seconds: f64,
}

/// `results.csv` (every case, sorted by name) and `failures.csv` (the unsuccessful ones) into `dir`.
pub fn write_csvs(dir: &Path, rows: &[Row]) -> Result<()> {
    let mut sorted: Vec<&Row> = rows.iter().collect();
    sorted.sort_by(|a, b| a.name.cmp(&b.name));
    let results: String = sorted.iter().map(|r| format!("{},{},{:.3}\n", r.name, r.status, r.seconds)).collect();
    let failures: String = sorted.iter().filter(|r| !r.status.is_success()).map(|r| format!("{},{}\n", r.name, r.status)).collect();
    for (name, text) in [("results.csv", results), ("failures.csv", failures)] {
        let p = dir.join(name);
        std::fs::write(&p, text).map_err(|e| Error::io(p.display().to_string(), e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn baselines_take_every_status_and_refuse_duplicates() {
        let b = Baseline::parse("# c\numbrage.a,Fail\numbrage.b,Crash\numbrage.c,Timeout,1.0\nstencil.x-1,Fail\n").unwrap();
        assert_eq!(b.cases["umbrage.a"], Judged::Fail);
        assert_eq!(b.cases["umbrage.c"], Judged::Timeout);
        assert_eq!(b.cases["umbrage.stencil.xm1"], Judged::Fail);
        assert!(Baseline::parse("umbrage.a,Fail\numbrage.a,Fail\n").is_err());
        assert!(Baseline::parse("umbrage.a,Bogus\n").is_err());
        assert!(Baseline::parse("umbrage.a\n").is_err());
    }

    #[test]
    fn judging_follows_deqp_runner() {
        use Judged::*;
        assert_eq!(Judged::with_baseline(Code::Fail, Some(Fail)), ExpectedFail);
        assert_eq!(Judged::with_baseline(Code::Timeout, Some(Timeout)), ExpectedFail);
        assert_eq!(Judged::with_baseline(Code::Timeout, Some(Crash)), Timeout);
        assert_eq!(Judged::with_baseline(Code::Crash, Some(Crash)), ExpectedFail);
        assert_eq!(Judged::with_baseline(Code::Pass, Some(Timeout)), UnexpectedImprovement(Code::Pass));
        assert_eq!(Judged::with_baseline(Code::NotSupported, Some(Fail)), UnexpectedImprovement(Code::NotSupported));
        assert_eq!(Judged::with_baseline(Code::Fail, None), Fail);
        assert!(!UnexpectedImprovement(Code::Pass).is_success());
        assert_eq!(UnexpectedImprovement(Code::NotSupported).to_string(), "UnexpectedImprovement(Skip)");
        for s in
            ["Pass", "Fail", "Skip", "Crash", "Timeout", "Flake", "KnownFlake", "Missing", "ExpectedFail", "UnexpectedImprovement(Pass)"]
        {
            assert_eq!(s.parse::<Judged>().unwrap().to_string(), s);
        }
    }

    #[test]
    fn regexes_read_as_deqp_runner_does() {
        let r = Regexes::parse(&["# why\numbrage.a.b\numbrage\\.c\\..*_on$\n".into()]).unwrap();
        assert!(r.is_match("umbrage.a.b"));
        assert!(r.is_match("umbrage.a.b.more"));
        assert!(!r.is_match("umbrage.aXb"), "dots of a plain line are literal");
        assert!(r.is_match("umbrage.c.x.clamp_on"));
        assert!(!r.is_match("umbrage.c.x.clamp_off"));
        assert!(Regexes::parse(&["umbrage.a,Fail".into()]).is_err());
        assert!(!Regexes::default().is_match("x"));
    }
}
