//! Result codes from the Rust errors (one to one), the thread-local last-error message, and the
//! panic boundary every entry point runs inside.

use crate::types::UmbrageResult::{self, *};
use engine::error::Misuse;
use engine::Error;
use std::cell::RefCell;
use std::ffi::{c_char, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// A failure at the boundary: its code and its message.
#[derive(Debug)]
pub struct CError {
    pub code: UmbrageResult,
    pub message: String,
}

impl CError {
    pub fn new(code: UmbrageResult, message: impl Into<String>) -> CError {
        CError { code, message: message.into() }
    }
    pub fn null(what: &str) -> CError {
        CError::new(UMBRAGE_ERROR_NULL_POINTER, format!("{what} is NULL"))
    }
    pub fn argument(what: &str, msg: impl std::fmt::Display) -> CError {
        CError::new(UMBRAGE_ERROR_ARGUMENT, format!("{what}: {msg}"))
    }
}

impl From<Error> for CError {
    fn from(e: Error) -> CError {
        CError { code: code_of(&e), message: e.to_string() }
    }
}

/// The code of a Rust error: one per `Error` variant, one per `Misuse` variant. Both enums are
/// `#[non_exhaustive]`: a variant added to the engine without a code here maps to
/// `UMBRAGE_ERROR_OTHER` until it gets one (the test below lists every variant there is).
pub fn code_of(e: &Error) -> UmbrageResult {
    match e {
        Error::Input { .. } => UMBRAGE_ERROR_INPUT,
        Error::Mesh { .. } => UMBRAGE_ERROR_MESH,
        Error::UnknownName { .. } => UMBRAGE_ERROR_UNKNOWN_NAME,
        Error::NoDevice(_) => UMBRAGE_ERROR_NO_DEVICE,
        Error::Vulkan { .. } => UMBRAGE_ERROR_VULKAN,
        Error::Allocation { .. } => UMBRAGE_ERROR_ALLOCATION,
        Error::OutOfMemory { .. } => UMBRAGE_ERROR_OUT_OF_MEMORY,
        Error::Unsupported(_) => UMBRAGE_ERROR_UNSUPPORTED,
        Error::Validation { .. } => UMBRAGE_ERROR_VALIDATION,
        Error::Internal(_) => UMBRAGE_ERROR_INTERNAL,
        Error::InvalidDesc { .. } => UMBRAGE_ERROR_INVALID_DESC,
        Error::Io { .. } => UMBRAGE_ERROR_IO,
        Error::Misuse(m) => match m {
            Misuse::LightIndex { .. } => UMBRAGE_ERROR_LIGHT_INDEX,
            Misuse::SlotOutOfRange { .. } => UMBRAGE_ERROR_SLOT_OUT_OF_RANGE,
            Misuse::ForeignFrame => UMBRAGE_ERROR_FOREIGN_FRAME,
            Misuse::StaleFrame { .. } => UMBRAGE_ERROR_STALE_FRAME,
            Misuse::UnknownId { .. } => UMBRAGE_ERROR_UNKNOWN_ID,
            Misuse::ForeignId { .. } => UMBRAGE_ERROR_FOREIGN_ID,
            Misuse::NotConfigured { .. } => UMBRAGE_ERROR_NOT_CONFIGURED,
            Misuse::Order(_) => UMBRAGE_ERROR_ORDER,
            Misuse::Argument { .. } => UMBRAGE_ERROR_ARGUMENT,
            _ => UMBRAGE_ERROR_OTHER,
        },
        _ => UMBRAGE_ERROR_OTHER,
    }
}

/// Whether a code poisons the pass it came from.
pub fn poisons(code: UmbrageResult) -> bool {
    matches!(code, UMBRAGE_ERROR_INTERNAL | UMBRAGE_ERROR_PANIC)
}

thread_local! {
    /// The message of the last failed call on this thread (NUL-terminated for C).
    static LAST: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last(message: &str) {
    let c = CString::new(message.replace('\0', "\\0")).unwrap_or_default();
    LAST.with(|l| *l.borrow_mut() = c);
}

/// Runs `f` inside the panic boundary: its error becomes a code and this thread's message; a
/// panic becomes `UMBRAGE_ERROR_PANIC` with the panic's message. Success clears nothing (the
/// message is that of the last *failed* call).
pub fn boundary(f: impl FnOnce() -> Result<(), CError>) -> UmbrageResult {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => UMBRAGE_SUCCESS,
        Ok(Err(e)) => {
            set_last(&e.message);
            e.code
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic without a message".into());
            set_last(&format!("internal error (a bug in umbrage, please report it): panic: {what}"));
            UMBRAGE_ERROR_PANIC
        }
    }
}

/// Copies this thread's last error message into `buffer` (`capacity` bytes, NUL-terminated,
/// cut at a character boundary when short) and returns the length of the whole message
/// without its NUL, so a host can call once with NULL/0 to size its buffer.
///
/// # Safety
/// `buffer` is NULL, or valid for `capacity` bytes of writes.
pub unsafe fn copy_last(buffer: *mut c_char, capacity: usize) -> usize {
    LAST.with(|l| {
        let l = l.borrow();
        let bytes = l.as_bytes();
        if !buffer.is_null() && capacity > 0 {
            let mut n = bytes.len().min(capacity - 1);
            // never cut a UTF-8 character in two
            while n > 0 && n < bytes.len() && (bytes[n] & 0xC0) == 0x80 {
                n -= 1;
            }
            // SAFETY: the caller's contract: `buffer` holds `capacity` > n bytes.
            unsafe {
                std::ptr::copy_nonoverlapping(bytes.as_ptr(), buffer.cast::<u8>(), n);
                *buffer.add(n) = 0;
            }
        }
        bytes.len()
    })
}

/// The last error message as a pointer valid until this thread's next failed call.
pub fn last_ptr() -> *const c_char {
    LAST.with(|l| l.borrow().as_ptr())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every Error and Misuse variant has its own code, and the codes are the pinned values.
    #[test]
    fn codes_are_one_to_one() {
        let errors = vec![
            (Error::input("f", "m"), 1),
            (Error::mesh("m", "x"), 2),
            (Error::UnknownName { what: "scene", name: "x".into(), expected: "y".into() }, 3),
            (Error::NoDevice("x".into()), 4),
            (Error::Vulkan { call: "vkX", result: ash::vk::Result::ERROR_DEVICE_LOST }, 5),
            (Error::OutOfMemory { name: "x".into(), size: 1, used: 1, budget: 1 }, 7),
            (Error::Unsupported("x".into()), 8),
            (Error::Validation { count: 1, first: "x".into() }, 9),
            (Error::Internal("x".into()), 10),
            (Error::desc("f", "x"), 11),
            (Error::io("p", std::io::Error::other("x")), 13),
            (Misuse::LightIndex { index: 1, lights: 1 }.into(), 100),
            (Misuse::SlotOutOfRange { slot: 1, slots: 1 }.into(), 101),
            (Misuse::ForeignFrame.into(), 102),
            (Misuse::StaleFrame { slot: 0, serial: 0, current: 1 }.into(), 103),
            (Misuse::UnknownId { what: "caster", id: "1".into() }.into(), 104),
            (Misuse::ForeignId { what: "caster", id: "1".into(), owner: 0, this: 1 }.into(), 105),
            (Misuse::NotConfigured { call: "x", needs: "y" }.into(), 106),
            (Misuse::Order("x".into()).into(), 107),
            (Error::argument("x", "y"), 108),
        ];
        let mut seen = std::collections::BTreeSet::new();
        for (e, want) in &errors {
            let code = code_of(e) as i32;
            assert_eq!(code, *want, "{e:?}");
            assert!(seen.insert(code), "code {code} twice");
        }
        // Error::Allocation (6) needs a gpu-allocator error to build: its arm is above.
        assert_eq!(UMBRAGE_ERROR_ALLOCATION as i32, 6);
    }

    #[test]
    fn panics_become_a_code_and_a_message() {
        let r = boundary(|| panic!("boom"));
        assert_eq!(r, UMBRAGE_ERROR_PANIC);
        let mut buf = [0 as c_char; 256];
        // SAFETY: `buf` holds 256 bytes.
        let n = unsafe { copy_last(buf.as_mut_ptr(), buf.len()) };
        // SAFETY: copy_last NUL-terminated it.
        let s = unsafe { std::ffi::CStr::from_ptr(buf.as_ptr()) }.to_string_lossy().into_owned();
        assert_eq!(n, s.len());
        assert!(s.contains("boom"), "{s}");
    }

    #[test]
    fn short_buffers_are_cut_and_terminated() {
        let _ = boundary(|| Err(CError::argument("field", "é".repeat(10))));
        let mut buf = [1 as c_char; 4];
        // SAFETY: `buf` holds 4 bytes.
        let n = unsafe { copy_last(buf.as_mut_ptr(), buf.len()) };
        assert_eq!(n, "field: ".len() + 20);
        assert_eq!(buf[3], 0);
    }
}
