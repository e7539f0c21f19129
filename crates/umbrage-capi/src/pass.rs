//! The pass behind an `UmbragePass` handle: the registry of live passes (a handle is a number,
//! never a pointer, so a destroyed or made-up handle is an error), the frames each ring slot
//! holds, and the caster and sphere ids handed to C.

use crate::error::{poisons, CError};
use crate::types::UmbrageResult::*;
use crate::types::*;
use engine::error::Misuse;
use engine::pass::{CasterId, PreparedFrame, ShadowPass, SphereId};
use gpu_allocator::vulkan::Allocator;
use std::collections::HashMap;
use std::ffi::{c_char, c_void, CString};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// One pass as C holds it.
pub struct State {
    /// The C handle's number (also a frame's and an id's pass).
    pub id: u64,
    /// Set by an internal error or a panic: only destroy works after it.
    pub poisoned: bool,
    /// Declared before the allocator: dropped first, freeing its memory into it.
    pub pass: ShadowPass,
    /// The pass's own allocator on the host's device.
    pub _allocator: Arc<Mutex<Allocator>>,
    /// Per ring slot, the frame last prepared in it.
    pub frames: Vec<Option<PreparedFrame>>,
    pub casters: HashMap<u64, CasterId>,
    pub spheres: HashMap<u64, SphereId>,
    /// The next caster or sphere id's low 32 bits (never reused).
    pub next_id: u32,
    pub warning: UmbrageWarningCallback,
    pub warning_user: *mut c_void,
}

// SAFETY: the warning callback's user data is the host's, used only on the thread that calls
// into the pass (the header's threading rule); everything else in `State` is Send.
unsafe impl Send for State {}

type Registry = Mutex<HashMap<u64, Arc<Mutex<State>>>>;

fn registry() -> &'static Registry {
    static R: std::sync::OnceLock<Registry> = std::sync::OnceLock::new();
    R.get_or_init(Default::default)
}

static NEXT_PASS: AtomicU64 = AtomicU64::new(1);

/// A fresh handle number (never reused in the process).
pub fn next_pass_id() -> u64 {
    NEXT_PASS.fetch_add(1, Ordering::Relaxed)
}

pub fn register(state: State) -> u64 {
    let id = state.id;
    registry().lock().unwrap_or_else(|e| e.into_inner()).insert(id, Arc::new(Mutex::new(state)));
    id
}

/// Removes the pass (dropping it once no call holds it).
pub fn unregister(id: u64) -> Option<Arc<Mutex<State>>> {
    registry().lock().unwrap_or_else(|e| e.into_inner()).remove(&id)
}

fn lookup(pass: UmbragePass) -> Result<Arc<Mutex<State>>, CError> {
    if pass.is_null() {
        return Err(CError::null("pass"));
    }
    let id = pass as usize as u64;
    registry()
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .get(&id)
        .cloned()
        .ok_or_else(|| CError::argument("pass", format!("{id:#x} is not a live pass (destroyed, or never created)")))
}

/// Runs `f` on the pass behind `pass`: refused when poisoned; an internal error or a panic
/// inside poisons it.
pub fn with_pass(pass: UmbragePass, f: impl FnOnce(&mut State) -> Result<(), CError>) -> UmbrageResult {
    crate::error::boundary(|| {
        let arc = lookup(pass)?;
        let mut guard: MutexGuard<'_, State> = arc.lock().unwrap_or_else(|e| e.into_inner());
        if guard.poisoned {
            return Err(CError::new(
                UMBRAGE_ERROR_POISONED,
                "the pass was poisoned by an earlier internal error or panic: only umbrage_pass_destroy works on it",
            ));
        }
        let state = &mut *guard;
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(state))) {
            Ok(Err(e)) => {
                if poisons(e.code) {
                    state.poisoned = true;
                }
                Err(e)
            }
            Ok(Ok(())) => Ok(()),
            Err(payload) => {
                state.poisoned = true;
                std::panic::resume_unwind(payload)
            }
        }
    })
}

impl State {
    /// The live frame `f` of this pass.
    pub fn frame(&self, f: &UmbrageFrame) -> Result<&PreparedFrame, CError> {
        if f.pass != self.id {
            return Err(engine::Error::from(Misuse::ForeignFrame).into());
        }
        let slots = self.frames.len();
        let held = self
            .frames
            .get(f.slot as usize)
            .ok_or(CError::from(engine::Error::from(Misuse::SlotOutOfRange { slot: f.slot as usize, slots })))?;
        match held {
            Some(p) if p.serial() == f.serial => Ok(p),
            Some(p) => Err(engine::Error::from(Misuse::StaleFrame { slot: f.slot as usize, serial: f.serial, current: p.serial() }).into()),
            None => Err(CError::argument("frame", format!("ring slot {} holds no prepared frame", f.slot))),
        }
    }

    /// A new id's number: the pass in the high 32 bits, a counter in the low.
    pub fn new_id(&mut self) -> Result<u64, CError> {
        self.next_id = self.next_id.checked_add(1).ok_or_else(|| CError::argument("id", "this pass made 2^32 ids"))?;
        Ok((self.id << 32) | self.next_id as u64)
    }

    fn check_id(&self, id: u64, what: &'static str) -> Result<(), CError> {
        let owner = id >> 32;
        if id != 0 && owner != self.id {
            return Err(engine::Error::from(Misuse::ForeignId { what, id: format!("{id:#x}"), owner, this: self.id }).into());
        }
        Ok(())
    }

    pub fn caster(&self, id: u64) -> Result<CasterId, CError> {
        self.check_id(id, "caster")?;
        self.casters
            .get(&id)
            .copied()
            .ok_or_else(|| engine::Error::from(Misuse::UnknownId { what: "caster", id: format!("{id:#x}") }).into())
    }

    pub fn sphere(&self, id: u64) -> Result<SphereId, CError> {
        self.check_id(id, "sphere caster")?;
        self.spheres
            .get(&id)
            .copied()
            .ok_or_else(|| engine::Error::from(Misuse::UnknownId { what: "sphere caster", id: format!("{id:#x}") }).into())
    }

    /// Sends each warning to the host's callback.
    pub fn warn(&self, warnings: &[String]) {
        if let Some(cb) = self.warning {
            for w in warnings {
                let c = CString::new(w.replace('\0', " ")).unwrap_or_default();
                // SAFETY: the host's callback, with its own user data and a string valid for
                // the call.
                unsafe { cb(self.warning_user, c.as_ptr() as *const c_char) };
            }
        }
    }
}
