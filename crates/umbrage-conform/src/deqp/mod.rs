//! `umbrage conform` where driver developers run their suites: deqp-runner (Mesa CI,
//! SwiftShader's regres, ChromeOS graphics QA) drives it unmodified through a `[[deqp]]` block,
//! and the same formats serve a run without it. See docs/conform/driver-ci.md.
//!
//! - **dEQP-compatible mode** ([`run_deqp`]): any `--deqp-*` flag ([`args`]). The cases come
//!   from `--deqp-caselist-file` and `--deqp-case`, by their public names ([`names`]:
//!   `umbrage.` + the short name); each prints `Test case 'NAME'..` and its status line
//!   (`  Pass (…)`, `  Fail (…)`, `  NotSupported (…)`, `  Crash (…)`, `  Timeout (…)`) as it
//!   finishes, and its record goes into the QPA log ([`qpa`]) with the failure images. The
//!   renderer probe's `umbrage.info.renderer`, `.version` and `.extensions` are answered. Nothing
//!   is written but the log (children work in a temporary directory).
//! - **Standalone** ([`run_standalone`]): `--baseline`, `--flakes`, `--skips`, `--fraction`,
//!   `--fraction-start` ([`baseline`]); unexpected results are run again and reported as
//!   `Flake` when they change; `results.csv` and `failures.csv` beside `conform.json` and
//!   `conform.md`.
//!
//! Both run the cases through [`exec`]: children of at most `--chunk` cases, a crash or a hang
//! pinned on the one case that caused it.

pub mod args;
pub mod baseline;
pub mod exec;
pub mod list;
pub mod names;
pub mod qpa;

use super::suite::{self, Report, SuiteOptions};
use super::{devices, report, RunArgs};
use args::DeqpArgs;
use baseline::{Baseline, Judged, Regexes, Row};
use exec::{Code, Done, Exec};
use std::collections::{HashMap, HashSet};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

/// The default unit timeout in dEQP-compatible mode: below deqp-runner's default per-test
/// timer (60 s), so that a hang is pinned by umbrage before the runner kills the process.
pub const DEQP_TIMEOUT_S: f64 = 30.0;

/// The default most cases of a configuration one child draws (the single-configuration units
/// take an eighth).
pub const DEFAULT_CHUNK: usize = 64;

/// The standalone driver-CI flags of `umbrage conform`.
#[derive(Clone, Debug, Default)]
pub struct CiArgs {
    /// `--baseline FILE`: `name,Status` lines.
    pub baseline: Option<PathBuf>,
    /// `--flakes FILE` (repeatable): regexes of known flaky cases.
    pub flakes: Vec<PathBuf>,
    /// `--skips FILE` (repeatable): regexes of cases not to run.
    pub skips: Vec<PathBuf>,
    /// `--fraction N`: run one case in N.
    pub fraction: Option<usize>,
    /// `--fraction-start K`: starting with the K-th (1-based).
    pub fraction_start: Option<usize>,
    /// `--chunk N`: most cases of a configuration per child.
    pub chunk: Option<usize>,
}

impl CiArgs {
    /// Whether any flag asks for the driver-CI run.
    pub fn any(&self) -> bool {
        self.baseline.is_some()
            || !self.flakes.is_empty()
            || !self.skips.is_empty()
            || self.fraction.is_some()
            || self.fraction_start.is_some()
    }
}

/// The names `umbrage conform --list` prints: the public names of the cases `filter` selects.
pub fn list(filter: &[String]) -> Vec<String> {
    list::all()
        .into_iter()
        .filter(|(p, s)| filter.is_empty() || filter.iter().any(|f| suite::matches(f, s) || suite::matches(f, p)))
        .map(|(p, _)| p)
        .collect()
}

fn exe() -> Result<PathBuf> {
    std::env::current_exe().map_err(|e| Error::io("the umbrage executable", e))
}

fn temp_scratch() -> PathBuf {
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.subsec_nanos()).unwrap_or(0);
    std::env::temp_dir().join(format!("umbrage-conform-{}-{nanos}", std::process::id()))
}

fn one_line(s: &str) -> String {
    let s = s.replace(['\n', '\r'], " ");
    if s.is_empty() {
        "-".into()
    } else {
        s
    }
}

/// The probe cases deqp-runner runs before a suite whose prefix it does not know.
const INFO: [&str; 3] = ["umbrage.info.renderer", "umbrage.info.version", "umbrage.info.extensions"];

fn device_extensions(ctx: &Context) -> Vec<String> {
    // SAFETY: `instance` and `physical` are the live handles of `ctx`, which outlives the call.
    let props = unsafe { ctx.instance.enumerate_device_extension_properties(ctx.physical) }.unwrap_or_default();
    let mut v: Vec<String> =
        props.iter().filter_map(|p| p.extension_name_as_c_str().ok().map(|c| c.to_string_lossy().into_owned())).collect();
    v.sort();
    v
}

/// `--deqp-vk-device-id=N`: the N-th physical device the loader enumerates (1-based, as
/// VK-GL-CTS counts), by its place rather than its name (two boards of one model have one
/// name): `UMBRAGE_DEVICE=#N` for this process's context and its children's.
fn set_device_by_id(id: usize) -> Result<()> {
    let all = devices::list()?;
    if id == 0 || id > all.len() {
        return Err(Error::NoDevice(format!("--deqp-vk-device-id={id}: there are {} Vulkan devices (1-based ids)", all.len())));
    }
    std::env::set_var("UMBRAGE_DEVICE", format!("#{id}"));
    Ok(())
}

/// Writes dEQP's `txt-caselist` output: `GROUP:` lines for each group, `TEST:` for each case.
fn write_txt_caselist(d: &DeqpArgs) -> Result<ExitCode> {
    let dir = d.export_path.clone().unwrap_or_else(|| PathBuf::from("."));
    let path = dir.join("umbrage-cases.txt");
    let mut s = String::new();
    let mut open: Vec<String> = Vec::new();
    for n in list::all_public() {
        let parts: Vec<&str> = n.split('.').collect();
        for depth in 1..parts.len() {
            let g = parts[..depth].join(".");
            if open.get(depth - 1) != Some(&g) {
                open.truncate(depth - 1);
                open.push(g.clone());
                s.push_str(&format!("GROUP: {g}\n"));
            }
        }
        open.truncate(parts.len() - 1);
        s.push_str(&format!("TEST: {n}\n"));
    }
    std::fs::write(&path, s).map_err(|e| Error::io(path.display().to_string(), e))?;
    println!("Test case list written to {}", path.display());
    Ok(ExitCode::SUCCESS)
}

/// The log, appended to as cases finish.
struct Log {
    file: Option<std::fs::File>,
    flush: bool,
}

impl Log {
    fn write(&mut self, s: &str) -> Result<()> {
        if let Some(f) = &mut self.file {
            f.write_all(s.as_bytes()).map_err(|e| Error::io("the QPA log", e))?;
            if self.flush {
                f.flush().map_err(|e| Error::io("the QPA log", e))?;
            }
        }
        Ok(())
    }
}

fn record(d: &Done) -> String {
    let mut texts = Vec::new();
    if !d.outcome.what.is_empty() {
        texts.push(d.outcome.what.clone());
    }
    if let Some(b) = &d.outcome.bug {
        texts.push(format!("known bug: {} ({})", b.title, b.url));
    }
    texts.push(one_line(&d.outcome.message));
    let mut images = Vec::new();
    for p in &d.outcome.images {
        match qpa::Image::from_png_file(Path::new(p)) {
            Ok(im) => images.push(im),
            Err(e) => texts.push(format!("image not embedded: {e}")),
        }
    }
    qpa::case_record(&d.public, d.code, &texts, &images, (d.outcome.seconds * 1e6) as u64)
}

/// The dEQP-compatible mode (see the module docs). Exits 0 when it ran (whatever the cases'
/// results, as dEQP does); an error (bad flags, unreadable case list, no device) is non-zero.
pub fn run_deqp(d: DeqpArgs, a: &RunArgs, chunk: Option<usize>, timeout_given: bool) -> Result<ExitCode> {
    if d.runmode.as_deref() == Some("txt-caselist") {
        return write_txt_caselist(&d);
    }
    let idx = list::Index::new();
    // The selection, in run order, and the names nothing matched.
    let mut picked: Vec<bool> = vec![false; idx.cases.len()];
    let mut info: Vec<&str> = Vec::new();
    let mut unknown: Vec<String> = Vec::new();
    if let Some(f) = &d.caselist_file {
        let text = std::fs::read_to_string(f).map_err(|e| Error::io(f.display().to_string(), e))?;
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
            if let Some(i) = INFO.iter().position(|n| *n == line) {
                info.push(INFO[i]);
            } else if line.contains('*') {
                idx.select(&[line.to_string()]).into_iter().for_each(|i| picked[i] = true);
            } else {
                match idx.find(line) {
                    Some(i) => picked[i] = true,
                    None => unknown.push(line.to_string()),
                }
            }
        }
    }
    if !d.cases.is_empty() {
        idx.select(&d.cases).into_iter().for_each(|i| picked[i] = true);
        for n in INFO {
            if d.cases.iter().any(|p| names::glob(p, n)) && !info.contains(&n) {
                info.push(n);
            }
        }
        for p in d.cases.iter().filter(|p| !p.contains('*')) {
            if idx.find(p).is_none() && !INFO.contains(&p.as_str()) {
                unknown.push(p.clone());
            }
        }
    }
    if d.caselist_file.is_none() && d.cases.is_empty() {
        picked.iter_mut().for_each(|p| *p = true);
    }
    if let Some(id) = d.device_id {
        set_device_by_id(id)?;
    } else if let Some(dev) = &a.device {
        devices::find(dev)?;
        std::env::set_var("UMBRAGE_DEVICE", dev);
    }

    let mut log = Log { file: None, flush: d.log_flush };
    if let Some(p) = &d.log {
        let f = std::fs::File::create(p).map_err(|e| Error::io(p.display().to_string(), e))?;
        log.file = Some(f);
        println!("Writing test log into {}", p.display());
    }
    println!("dEQP Core umbrage-{} (0x00000000) starting..", env!("CARGO_PKG_VERSION"));
    println!("  target implementation = 'umbrage conform'");
    if !d.ignored.is_empty() {
        println!("  ignored: {}", d.ignored.join(" "));
    }
    log.write(&qpa::session_header(&d.command_line))?;

    let ctx = Context::any_version(umbrage::gpu::context::validation_requested())?;
    let mut counts: HashMap<Code, usize> = HashMap::new();
    let mut emit = |log: &mut Log, public: &str, code: Code, msg: &str, rec: String, announced: bool| -> Result<()> {
        if !announced {
            println!("\nTest case '{public}'..");
        }
        println!("  {} ({})", code.name(), one_line(msg));
        let _ = std::io::stdout().flush();
        *counts.entry(code).or_default() += 1;
        log.write(&rec)
    };
    for n in &info {
        let texts: Vec<String> = match *n {
            "umbrage.info.renderer" => vec![ctx.info.name.clone()],
            "umbrage.info.version" => {
                vec![format!("Vulkan {} ({} {})", ctx.info.api_version, ctx.info.driver, ctx.info.driver_info).trim().to_string()]
            }
            _ => device_extensions(&ctx),
        };
        let msg = texts.first().cloned().unwrap_or_default();
        emit(&mut log, n, Code::Pass, &msg, qpa::case_record(n, Code::Pass, &texts, &[], 0), false)?;
    }
    for n in &unknown {
        let msg = format!("'{n}' is not a case of umbrage {} (see umbrage conform --list)", env!("CARGO_PKG_VERSION"));
        emit(&mut log, n, Code::Fail, &msg, qpa::case_record(n, Code::Fail, std::slice::from_ref(&msg), &[], 0), false)?;
    }

    let selected: Vec<String> = (0..idx.cases.len()).filter(|&i| picked[i]).map(|i| idx.cases[i].1.clone()).collect();
    let scratch = temp_scratch();
    let timeout = if timeout_given { a.timeout_s } else { DEQP_TIMEOUT_S };
    let jobs = if a.jobs == 0 { 1 } else { a.jobs };
    let ex =
        Exec::chunked(exe()?, Duration::from_secs_f64(timeout), jobs, scratch.clone(), scratch.clone(), chunk.unwrap_or(DEFAULT_CHUNK));
    let opts = SuiteOptions { break_op: None, ..Default::default() };
    let announced: std::cell::RefCell<HashSet<String>> = Default::default();
    let mut failure: Option<Error> = None;
    let result = exec::run(
        &ctx,
        &selected,
        &ex,
        &opts,
        &mut |public| {
            println!("\nTest case '{public}'..");
            let _ = std::io::stdout().flush();
            announced.borrow_mut().insert(public.to_string());
        },
        &mut |done| {
            let rec = record(&done);
            let was = announced.borrow_mut().remove(&done.public);
            if let Err(e) = emit(&mut log, &done.public, done.code, &done.outcome.message, rec, was) {
                failure.get_or_insert(e);
            }
        },
    );
    let _ = std::fs::remove_dir_all(&scratch);
    result.map(|_| ())?;
    if let Some(e) = failure {
        return Err(e);
    }
    log.write(qpa::SESSION_END)?;
    let n = |c: Code| counts.get(&c).copied().unwrap_or(0);
    let total: usize = counts.values().sum();
    println!("\nDONE!\n\nTest run totals:");
    println!("  Passed:        {}/{total}", n(Code::Pass));
    println!("  Failed:        {}/{total}", n(Code::Fail) + n(Code::Crash) + n(Code::Timeout));
    println!("  Not supported: {}/{total}", n(Code::NotSupported));
    println!("  Warnings:      0/{total}");
    println!("  Waived:        0/{total}");
    Ok(ExitCode::SUCCESS)
}

/// The standalone driver-CI run (see the module docs): exit 0 when every case's verdict is a
/// success (deqp-runner's rule), 1 otherwise.
pub fn run_standalone(ctx: &Context, a: &RunArgs, filter: &[String], out: &Path, opts: &SuiteOptions) -> Result<ExitCode> {
    let start = Instant::now();
    let ci = &a.ci;
    let base = ci.baseline.as_deref().map(Baseline::load).transpose()?.unwrap_or_default();
    let flakes = Regexes::load(&ci.flakes)?;
    let skips = Regexes::load(&ci.skips)?;
    let (fraction, fstart) = (ci.fraction.unwrap_or(1), ci.fraction_start.unwrap_or(1));
    if fraction == 0 || fstart == 0 {
        return Err(Error::input("--fraction", "--fraction and --fraction-start count from 1"));
    }
    let all: Vec<(String, String)> = list::all()
        .into_iter()
        .filter(|(p, s)| filter.is_empty() || filter.iter().any(|f| suite::matches(f, s) || suite::matches(f, p)))
        .collect();
    let mine = names::fraction(&all, fraction, fstart);
    let (skipped, to_run): (Vec<_>, Vec<_>) = mine.into_iter().partition(|(p, _)| skips.is_match(p));
    let jobs = match a.jobs {
        0 => std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        n => n,
    };
    let ex = Exec::chunked(
        exe()?,
        Duration::from_secs_f64(a.timeout_s),
        jobs,
        out.join("children"),
        out.to_path_buf(),
        ci.chunk.unwrap_or(DEFAULT_CHUNK),
    );
    let names_to_run: Vec<String> = to_run.iter().map(|(_, s)| s.clone()).collect();
    let mut first: Vec<Done> = Vec::new();
    let extras = exec::run(ctx, &names_to_run, &ex, opts, &mut |_| {}, &mut |d| first.push(d))?;
    let judge = |d: &Done| {
        let j = Judged::with_baseline(d.code, base.cases.get(&d.public).copied());
        if !j.is_success() && flakes.is_match(&d.public) {
            Judged::KnownFlake
        } else {
            j
        }
    };
    // Unexpected results once more: a changed status is a flake.
    let again: Vec<String> = first.iter().filter(|d| !judge(d).is_success()).map(|d| d.outcome.name.clone()).collect();
    let mut second: HashMap<String, Code> = HashMap::new();
    if !again.is_empty() {
        println!("running the {} unexpected results again", again.len());
        exec::run(ctx, &again, &ex, opts, &mut |_| {}, &mut |d| {
            second.insert(d.public.clone(), d.code);
        })?;
    }
    let mut rows: Vec<Row> = Vec::new();
    for d in &first {
        let mut j = judge(d);
        if second.get(&d.public).is_some_and(|c| *c != d.code) {
            j = Judged::Flake;
        }
        rows.push(Row { name: d.public.clone(), status: j, seconds: d.outcome.seconds });
    }
    for (p, _) in &skipped {
        rows.push(Row { name: p.clone(), status: Judged::Skip, seconds: 0.0 });
    }

    // The JSON and Markdown reports of the cases that ran, in run order.
    let order: HashMap<&str, usize> = all.iter().enumerate().map(|(i, (_, s))| (s.as_str(), i)).collect();
    let mut cases: Vec<suite::CaseOutcome> = first.iter().map(|d| d.outcome.clone()).collect();
    cases.sort_by_key(|c| order.get(c.name.as_str()).copied().unwrap_or(usize::MAX));
    let r = Report {
        device: ctx.info.clone(),
        features: ctx.features.clone(),
        validation: ctx.validation,
        subpixel_bits: ctx.limits.sub_pixel_precision_bits,
        filter: filter.to_vec(),
        formats: suite::format_support(ctx).into_iter().map(|(_, s)| s).collect(),
        configs: extras.configs,
        cases,
        legacy: extras.legacy,
        seconds: start.elapsed().as_secs_f64(),
        children: extras.children,
    };
    report::write_all(out, a.junit.as_deref(), &r)?;
    baseline::write_csvs(out, &rows)?;
    let _ = std::fs::remove_dir_all(out.join("children"));

    println!("{} | {} | Vulkan {}", r.device.name, r.device.driver_info, r.device.api_version);
    let mut tally: Vec<(String, usize)> = Vec::new();
    for row in &rows {
        let k = row.status.to_string();
        match tally.iter_mut().find(|(s, _)| *s == k) {
            Some((_, n)) => *n += 1,
            None => tally.push((k, 1)),
        }
    }
    tally.sort();
    let bad: Vec<&Row> = rows.iter().filter(|r| !r.status.is_success()).collect();
    for r in &bad {
        println!("{},{}", r.name, r.status);
    }
    let summary: Vec<String> = tally.iter().map(|(s, n)| format!("{s}: {n}")).collect();
    println!(
        "{}: {} cases (shard {fstart} of {fraction}), {} ({:.1} s)",
        if bad.is_empty() { "PASS" } else { "FAIL" },
        rows.len(),
        summary.join(", "),
        r.seconds
    );
    println!("reports: {0}/results.csv, {0}/failures.csv, {0}/conform.json, {0}/conform.md", out.display());
    Ok(if bad.is_empty() { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// `results.csv` and `failures.csv` of a classic run (no baseline: the raw statuses), beside its `conform.json`.
pub fn write_plain_csvs(out: &Path, r: &Report) -> Result<()> {
    let rows: Vec<Row> = r
        .cases
        .iter()
        .map(|c| {
            let code = Code::of(c.status);
            Row { name: names::public(&c.name), status: Judged::raw(code), seconds: c.seconds }
        })
        .collect();
    baseline::write_csvs(out, &rows)
}
