//! The panic boundary, status mapping, per-thread error message and pointer checks that
//! every entry point goes through.

use std::cell::RefCell;
use std::ffi::{CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

use wavg::ErrorKind;

use crate::types::wavg_status;

/// A failed call: its status and message.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: wavg_status,
    pub message: String,
}

impl Failure {
    /// An invalid-argument failure.
    pub(crate) fn arg(message: impl Into<String>) -> Self {
        Self {
            status: wavg_status::WAVG_STATUS_INVALID_ARGUMENT,
            message: message.into(),
        }
    }
}

/// The status of an error kind: the C ABI's one table from the library's error kinds
/// (a failed write is `WAVG_STATUS_IO` like a failed read; a failure of the library on
/// valid input is `WAVG_STATUS_PANIC`, the internal-error status).
pub(crate) const fn status_of(kind: ErrorKind) -> wavg_status {
    match kind {
        ErrorKind::InvalidArgument => wavg_status::WAVG_STATUS_INVALID_ARGUMENT,
        ErrorKind::InvalidMesh => wavg_status::WAVG_STATUS_INVALID_MESH,
        ErrorKind::Io | ErrorKind::Write => wavg_status::WAVG_STATUS_IO,
        ErrorKind::NoSolution => wavg_status::WAVG_STATUS_NO_SOLUTION,
        ErrorKind::Cancelled => wavg_status::WAVG_STATUS_CANCELLED,
        ErrorKind::Internal => wavg_status::WAVG_STATUS_PANIC,
        ErrorKind::OutOfMemory => wavg_status::WAVG_STATUS_OUT_OF_MEMORY,
    }
}

impl From<wavg::Error> for Failure {
    fn from(e: wavg::Error) -> Self {
        Self {
            status: status_of(e.kind()),
            message: e.message(),
        }
    }
}

// Layer and application errors convert through `wavg::Error`.
wavg::from_layer_errors!(Failure);

pub(crate) type Outcome = Result<(), Failure>;

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Stores `message` as this thread's last error (interior NULs are replaced).
pub(crate) fn set_last_error(message: &str) {
    let c = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Runs an entry point's body: a panic becomes `WAVG_STATUS_PANIC`, a failure sets this
/// thread's last error.
pub(crate) fn guard(body: impl FnOnce() -> Outcome) -> wavg_status {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => wavg_status::WAVG_STATUS_OK,
        Ok(Err(f)) => {
            set_last_error(&f.message);
            f.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last_error(&format!("internal error (please report): {what}"));
            wavg_status::WAVG_STATUS_PANIC
        }
    }
}

/// Runs a query that cannot fail (counts): a panic gives `fallback`.
pub(crate) fn guard_value<T>(fallback: T, body: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(body)).unwrap_or(fallback)
}

/// A shared reference from a handle pointer, or an invalid-argument failure for NULL.
///
/// # Safety
/// `ptr` must be NULL or point to a live `T`.
pub(crate) unsafe fn handle<'a, T>(ptr: *const T, what: &str) -> Result<&'a T, Failure> {
    // SAFETY: the caller guarantees `ptr` is NULL or valid.
    unsafe { ptr.as_ref() }.ok_or_else(|| Failure::arg(format!("{what} is NULL")))
}

/// A mutable reference from a handle pointer, or an invalid-argument failure for NULL.
///
/// # Safety
/// `ptr` must be NULL or point to a live `T` nobody else uses during the call.
pub(crate) unsafe fn handle_mut<'a, T>(ptr: *mut T, what: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: the caller guarantees `ptr` is NULL or valid and unaliased.
    unsafe { ptr.as_mut() }.ok_or_else(|| Failure::arg(format!("{what} is NULL")))
}

/// A slice of `len` elements at `ptr`; NULL is an error (even for `len == 0`, which
/// callers reject before).
///
/// # Safety
/// `ptr` must be NULL or point to `len` readable `T`.
pub(crate) unsafe fn slice<'a, T>(
    ptr: *const T,
    len: usize,
    what: &str,
) -> Result<&'a [T], Failure> {
    if ptr.is_null() {
        return Err(Failure::arg(format!("{what} is NULL")));
    }
    check_len::<T>(len, what)?;
    // SAFETY: non-NULL, the size fits in `isize`, and the caller guarantees `len` readable
    // elements.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// A mutable slice of `len` elements at `ptr`; NULL is an error.
///
/// # Safety
/// `ptr` must be NULL or point to `len` writable `T` not otherwise referenced.
pub(crate) unsafe fn slice_mut<'a, T>(
    ptr: *mut T,
    len: usize,
    what: &str,
) -> Result<&'a mut [T], Failure> {
    if ptr.is_null() {
        return Err(Failure::arg(format!("{what} is NULL")));
    }
    check_len::<T>(len, what)?;
    // SAFETY: non-NULL, the size fits in `isize`, and the caller guarantees `len` writable,
    // unaliased elements.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
}

/// An optional output array: `None` for NULL; a length whose byte size does not fit in
/// `isize` is an invalid-argument failure.
///
/// # Safety
/// `ptr` must be NULL or hold `len` writable, unaliased elements.
pub(crate) unsafe fn optional<'a, T>(
    ptr: *mut T,
    len: usize,
    what: &str,
) -> Result<Option<&'a mut [T]>, Failure> {
    if ptr.is_null() {
        return Ok(None);
    }
    // SAFETY: per this function's contract.
    unsafe { slice_mut(ptr, len, what) }.map(Some)
}

/// No array of `len` elements of `T` can exist when its size in bytes overflows `isize`
/// (the caller's count is wrong): an invalid-argument failure, checked before a slice is
/// made of it.
fn check_len<T>(len: usize, what: &str) -> Result<(), Failure> {
    match len.checked_mul(std::mem::size_of::<T>()) {
        Some(bytes) if bytes <= isize::MAX as usize => Ok(()),
        _ => Err(Failure::arg(format!(
            "{what}: {len} elements is too large for an array"
        ))),
    }
}

/// `a * b`, or an invalid-argument failure when it overflows.
pub(crate) fn product(a: usize, b: usize, what: &str) -> Result<usize, Failure> {
    a.checked_mul(b)
        .ok_or_else(|| Failure::arg(format!("{what} is too large")))
}

/// The ABI version of the library as loaded: compare with `WAVG_ABI_VERSION` from the
/// header you compiled against. Thread-safe; cannot fail.
#[unsafe(no_mangle)]
pub extern "C" fn wavg_abi_version() -> u32 {
    crate::WAVG_ABI_VERSION
}

/// The library's version as loaded, `"MAJOR.MINOR.PATCH"` (the workspace version, as
/// `WAVG_VERSION_MAJOR`/`_MINOR`/`_PATCH` of the header). The string is static: never free
/// it. Thread-safe; cannot fail.
#[unsafe(no_mangle)]
pub extern "C" fn wavg_version() -> *const c_char {
    const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "\0");
    VERSION.as_ptr().cast()
}

/// The message of the calling thread's last failed call ("" if none failed yet). The
/// string is owned by the library and stays valid until the thread's next call into the
/// library; copy it to keep it. Thread-safe (each thread has its own message).
#[unsafe(no_mangle)]
pub extern "C" fn wavg_last_error() -> *const c_char {
    guard_value(c"".as_ptr(), || LAST_ERROR.with(|e| e.borrow().as_ptr()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CStr;

    fn last() -> String {
        // SAFETY: wavg_last_error returns a valid NUL-terminated string.
        unsafe { CStr::from_ptr(wavg_last_error()) }
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn the_version_is_the_packages() {
        // SAFETY: wavg_version returns a static NUL-terminated string.
        let v = unsafe { CStr::from_ptr(wavg_version()) };
        assert_eq!(v.to_str(), Ok(env!("CARGO_PKG_VERSION")));
        let numbers = [
            crate::WAVG_VERSION_MAJOR,
            crate::WAVG_VERSION_MINOR,
            crate::WAVG_VERSION_PATCH,
        ]
        .map(|n| n.to_string())
        .join(".");
        assert_eq!(numbers, env!("CARGO_PKG_VERSION"));
    }

    #[test]
    fn a_panic_becomes_a_status_and_a_message() {
        assert_eq!(last(), "");
        let s = guard(|| panic!("boom {}", 7));
        assert_eq!(s, wavg_status::WAVG_STATUS_PANIC);
        assert!(last().contains("boom 7"), "{}", last());
        assert_eq!(guard(|| Ok(())), wavg_status::WAVG_STATUS_OK);
        // A success leaves the last failure's message in place.
        assert!(last().contains("boom 7"));
        assert_eq!(guard_value(3, || panic!("x")), 3);
    }

    #[test]
    fn failures_set_their_message_per_thread() {
        let s = guard(|| Err(Failure::arg("bad\0thing")));
        assert_eq!(s, wavg_status::WAVG_STATUS_INVALID_ARGUMENT);
        assert_eq!(last(), "bad thing");
        std::thread::spawn(|| assert_eq!(last(), ""))
            .join()
            .unwrap();
    }
}
