//! Fault injection a host installs: a memory budget that makes allocations fail, and injected
//! results from queue submission and presentation. Nothing is injected unless a host asks:
//! the engine reads no environment variable; the `umbrage` command line installs what its
//! `UMBRAGE_FAULT` and `UMBRAGE_MEMORY_BUDGET` say ([`parse_faults`], [`parse_bytes`]).
//!
//! Real devices rarely run out of memory or get lost on demand, so the error paths they take
//! are exercised here by injection:
//!
//! - **Memory budget** ([`set_memory_budget`]) caps the bytes the crate's buffers and images
//!   may hold in one allocator. An allocation that would cross it fails with
//!   [`crate::Error::OutOfMemory`] before any Vulkan memory is taken, and the object it was
//!   for is destroyed again.
//! - **Injected results** ([`set_faults`]; text form `<point>=<result>@<n>[,...]`) make the
//!   `n`-th call (1-based, counted per point) at `point` return `result` instead of calling
//!   Vulkan. Points: `submit` (every `vkQueueSubmit` of the crate), `present` (the viewer's
//!   `vkQueuePresentKHR` and `vkAcquireNextImageKHR`), `alloc` (every buffer and image memory
//!   allocation, failing with [`crate::Error::Allocation`]). Results: `device_lost`,
//!   `out_of_date`, `out_of_device_memory`, `out_of_host_memory`, `surface_lost`. For example
//!   `submit=device_lost@3` loses the device on the third frame.
//!
//! [`set_faults`] and [`set_memory_budget`] act on the whole process (a command line's run);
//! [`set_thread_faults`] on the calling thread alone, so that a test injecting faults does not
//! reach the tests running beside it in the same process.

use ash::vk;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};

/// Where a fault can be injected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultPoint {
    /// `vkQueueSubmit`, in every frame and one-shot upload.
    Submit,
    /// `vkAcquireNextImageKHR` and `vkQueuePresentKHR` (windowed clients).
    Present,
    /// Every memory allocation of the crate's buffers and images (before gpu-allocator is
    /// asked): the object is destroyed again and the error is [`crate::Error::Allocation`].
    Alloc,
}

impl FaultPoint {
    fn index(self) -> usize {
        match self {
            FaultPoint::Submit => 0,
            FaultPoint::Present => 1,
            FaultPoint::Alloc => 2,
        }
    }
    fn parse(s: &str) -> Option<FaultPoint> {
        match s {
            "submit" => Some(FaultPoint::Submit),
            "present" => Some(FaultPoint::Present),
            "alloc" => Some(FaultPoint::Alloc),
            _ => None,
        }
    }
}

/// One injected fault: the `nth` call at `point` returns `result`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fault {
    /// Where.
    pub point: FaultPoint,
    /// The 1-based call number at that point.
    pub nth: u64,
    /// What the call returns instead of calling Vulkan.
    pub result: vk::Result,
}

/// Parses an `UMBRAGE_FAULT` value (see the module docs): `submit=device_lost@3,present=out_of_date@1`.
pub fn parse_faults(spec: &str) -> Result<Vec<Fault>, String> {
    let mut out = Vec::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let bad = || format!("UMBRAGE_FAULT item '{item}': expected <submit|present|alloc>=<result>@<n>");
        let (point, rest) = item.split_once('=').ok_or_else(bad)?;
        let (result, nth) = rest.split_once('@').ok_or_else(bad)?;
        let point = FaultPoint::parse(point.trim()).ok_or_else(bad)?;
        let nth: u64 = nth.trim().parse().ok().filter(|&n| n > 0).ok_or_else(bad)?;
        let result = match result.trim() {
            "device_lost" => vk::Result::ERROR_DEVICE_LOST,
            "out_of_date" => vk::Result::ERROR_OUT_OF_DATE_KHR,
            "out_of_device_memory" => vk::Result::ERROR_OUT_OF_DEVICE_MEMORY,
            "out_of_host_memory" => vk::Result::ERROR_OUT_OF_HOST_MEMORY,
            "surface_lost" => vk::Result::ERROR_SURFACE_LOST_KHR,
            _ => return Err(bad()),
        };
        out.push(Fault { point, nth, result });
    }
    Ok(out)
}

/// Parses a byte count with an optional `K`, `M` or `G` suffix (powers of 1024).
pub fn parse_bytes(s: &str) -> Option<u64> {
    let s = s.trim();
    let (digits, mult) = match s.char_indices().last()? {
        (i, 'k' | 'K') => (&s[..i], 1u64 << 10),
        (i, 'm' | 'M') => (&s[..i], 1 << 20),
        (i, 'g' | 'G') => (&s[..i], 1 << 30),
        _ => (s, 1),
    };
    digits.trim().parse::<u64>().ok()?.checked_mul(mult)
}

struct State {
    faults: Mutex<Vec<Fault>>,
    calls: [AtomicU64; 3],
    /// `u64::MAX` = no budget.
    budget: AtomicU64,
}

fn state() -> &'static State {
    static STATE: OnceLock<State> = OnceLock::new();
    STATE.get_or_init(|| State {
        faults: Mutex::new(Vec::new()),
        calls: [AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0)],
        budget: AtomicU64::new(u64::MAX),
    })
}

thread_local! {
    /// The calling thread's own faults and call counts ([`set_thread_faults`]): while set, they
    /// replace the process's on this thread, and this thread's calls do not count there.
    static THREAD: std::cell::RefCell<Option<(Vec<Fault>, [u64; 3])>> = const { std::cell::RefCell::new(None) };
}

/// Replaces the process's injected faults (and restarts the call counts); `[]` turns
/// injection off.
pub fn set_faults(faults: &[Fault]) {
    let s = state();
    *s.faults.lock().unwrap_or_else(|p| p.into_inner()) = faults.to_vec();
    for c in &s.calls {
        c.store(0, Ordering::SeqCst);
    }
}

/// Injects `faults` on the calling thread only, counting this thread's calls from zero; `None`
/// goes back to the process's faults. For tests that share a process with other tests.
pub fn set_thread_faults(faults: Option<&[Fault]>) {
    THREAD.with(|t| *t.borrow_mut() = faults.map(|f| (f.to_vec(), [0; 3])));
}

/// Counts one call at `point` and returns the injected result for it, if any. Callers return
/// it as if Vulkan had.
pub fn inject(point: FaultPoint) -> Option<vk::Result> {
    let own = THREAD.with(|t| {
        t.borrow_mut().as_mut().map(|(faults, calls)| {
            calls[point.index()] += 1;
            let n = calls[point.index()];
            faults.iter().find(|f| f.point == point && f.nth == n).map(|f| f.result)
        })
    });
    if let Some(result) = own {
        return result;
    }
    let s = state();
    let n = s.calls[point.index()].fetch_add(1, Ordering::SeqCst) + 1;
    let faults = s.faults.lock().unwrap_or_else(|p| p.into_inner());
    faults.iter().find(|f| f.point == point && f.nth == n).map(|f| f.result)
}

/// Sets (or with `None` removes) the memory budget in bytes per allocator.
pub fn set_memory_budget(bytes: Option<u64>) {
    state().budget.store(bytes.unwrap_or(u64::MAX), Ordering::SeqCst);
}

/// The memory budget in bytes, if one is set.
pub fn memory_budget() -> Option<u64> {
    match state().budget.load(Ordering::SeqCst) {
        u64::MAX => None,
        b => Some(b),
    }
}

/// Checks that `size` more bytes fit `allocator`'s budget (`name` labels the error), and counts
/// one allocation for [`FaultPoint::Alloc`].
pub(crate) fn check_budget(allocator: &gpu_allocator::vulkan::Allocator, name: &str, size: u64) -> crate::Result<()> {
    if let Some(result) = inject(FaultPoint::Alloc) {
        let source = match result {
            vk::Result::ERROR_OUT_OF_DEVICE_MEMORY => gpu_allocator::AllocationError::OutOfMemory,
            other => gpu_allocator::AllocationError::Internal(format!("injected {other:?} (fault injection)")),
        };
        return Err(crate::Error::Allocation { name: name.to_string(), size, source });
    }
    let Some(budget) = memory_budget() else { return Ok(()) };
    let used = allocator.generate_report().total_allocated_bytes;
    if used.saturating_add(size) > budget {
        return Err(crate::Error::OutOfMemory { name: name.to_string(), size, used, budget });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_fault_specs() {
        let f = parse_faults("submit=device_lost@3, present=out_of_date@1").unwrap();
        assert_eq!(f.len(), 2);
        assert_eq!(f[0], Fault { point: FaultPoint::Submit, nth: 3, result: vk::Result::ERROR_DEVICE_LOST });
        assert_eq!(f[1].result, vk::Result::ERROR_OUT_OF_DATE_KHR);
        for bad in ["submit", "submit=device_lost", "submit=device_lost@0", "draw=device_lost@1", "submit=oops@1", "submit=device_lost@x"] {
            assert!(parse_faults(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_faults("").unwrap(), vec![]);
    }

    #[test]
    fn parses_byte_counts() {
        assert_eq!(parse_bytes("4096"), Some(4096));
        assert_eq!(parse_bytes("64K"), Some(64 << 10));
        assert_eq!(parse_bytes("3m"), Some(3 << 20));
        assert_eq!(parse_bytes("2G"), Some(2 << 30));
        assert_eq!(parse_bytes(""), None);
        assert_eq!(parse_bytes("M"), None);
        assert_eq!(parse_bytes("-1"), None);
        assert_eq!(parse_bytes("99999999999999999999G"), None);
    }
}
