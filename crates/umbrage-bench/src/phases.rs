//! Where the suite's time goes: a clock that closes a [`Phase`] at each lap (wall and CPU
//! seconds, points measured and shared), and the machine's conditions (the process's CPU time,
//! the load average) that the report states beside every timing.

use super::report::Phase;
use std::time::Instant;

/// Laps of the run, each closing a phase.
pub(super) struct Clock {
    start: Instant,
    cpu0: Option<f64>,
    lap_wall: f64,
    lap_cpu: Option<f64>,
    /// The phases closed so far.
    pub phases: Vec<Phase>,
}

impl Clock {
    /// Starts the clock now.
    pub fn start() -> Clock {
        let cpu0 = process_cpu_seconds();
        Clock { start: Instant::now(), cpu0, lap_wall: 0.0, lap_cpu: cpu0, phases: Vec::new() }
    }

    /// Closes the phase `name` (merged into the last one where it has the same name): the
    /// time since the last lap, `points` measured and `shared` taken from earlier points.
    pub fn lap(&mut self, name: &str, points: usize, shared: usize) {
        let wall = self.start.elapsed().as_secs_f64();
        let cpu = process_cpu_seconds();
        let d_cpu = match (cpu, self.lap_cpu) {
            (Some(c), Some(l)) => Some(c - l),
            _ => None,
        };
        let d_wall = wall - self.lap_wall;
        (self.lap_wall, self.lap_cpu) = (wall, cpu);
        if let Some(p) = self.phases.last_mut().filter(|p| p.name == name) {
            p.wall_s += d_wall;
            p.cpu_s = p.cpu_s.zip(d_cpu).map(|(a, b)| a + b);
            p.points += points;
            p.shared_points += shared;
            p.load_average = load_average();
            return;
        }
        let load_average = load_average();
        self.phases.push(Phase { name: name.to_string(), wall_s: d_wall, cpu_s: d_cpu, points, shared_points: shared, load_average });
    }

    /// Wall seconds since the start.
    pub fn seconds(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// CPU seconds of the process since the start.
    pub fn cpu_seconds(&self) -> Option<f64> {
        process_cpu_seconds().map(|c| c - self.cpu0.unwrap_or(0.0))
    }
}

/// This process's CPU time (user + system, all threads: lavapipe's rasteriser threads too),
/// seconds; Linux only (`/proc/self/stat`, 100 ticks a second).
fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) in parentheses.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let (utime, stime): (f64, f64) = (f.get(11)?.parse().ok()?, f.get(12)?.parse().ok()?);
    Some((utime + stime) / 100.0)
}

/// The machine's 1-minute load average at the end of the run (other work competing for the
/// CPU slows lavapipe); Linux only.
pub(super) fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}
