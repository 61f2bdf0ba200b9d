//! Large arrays backed by huge pages. A derivation or subdivision step
//! writes tens or hundreds of megabytes into fresh memory, and with 4 KiB
//! pages much of its time goes to the kernel's page faults. The advice
//! changes how memory is backed, never what it holds.

/// The size of a huge page on the machines that have them.
const HUGE: usize = 2 << 20;

/// An empty `Vec` with room for `cap` elements; when that is at least two
/// huge pages, the kernel is asked to back it with huge pages before
/// anything is written to it.
pub(crate) fn with_capacity<T>(cap: usize) -> Vec<T> {
    let v: Vec<T> = Vec::with_capacity(cap);
    let bytes = cap.saturating_mul(std::mem::size_of::<T>());
    #[cfg(target_os = "linux")]
    if bytes >= 2 * HUGE {
        let start = v.as_ptr() as usize;
        let aligned = (start + HUGE - 1) & !(HUGE - 1);
        let end = (start + bytes) & !(HUGE - 1);
        if end > aligned {
            // SAFETY: the range lies inside `v`'s own allocation, and
            // MADV_HUGEPAGE never changes memory's contents; a failure
            // leaves ordinary pages.
            unsafe {
                libc::madvise(
                    aligned as *mut libc::c_void,
                    end - aligned,
                    libc::MADV_HUGEPAGE,
                );
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = bytes;
    v
}
