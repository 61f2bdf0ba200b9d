//! Large arrays backed by huge pages. A derivation or subdivision step
//! writes tens or hundreds of megabytes into fresh memory, and with 4 KiB
//! pages much of its time goes to the kernel's page faults. The advice
//! changes how memory is backed, never what it holds.

/// The size of a huge page on the machines that have them.
const HUGE: usize = 2 << 20;

/// An empty `Vec` with room for `cap` elements, in huge pages when that is
/// at least two of them.
pub(crate) fn with_capacity<T>(cap: usize) -> Vec<T> {
    let v = Vec::with_capacity(cap);
    advise(&v);
    v
}

/// Makes room for `additional` more elements of `v`, growing it at least
/// twofold; a large array is reallocated (which moves its pages without
/// copying them) and the new room asked for in huge pages.
pub(crate) fn grow<T: Copy>(v: &mut Vec<T>, additional: usize) {
    let need = v.len().saturating_add(additional);
    if need <= v.capacity() {
        return;
    }
    let cap = need.max(2 * v.capacity());
    if cap.saturating_mul(std::mem::size_of::<T>()) < 2 * HUGE {
        v.reserve(additional);
        return;
    }
    v.reserve_exact(cap - v.len());
    advise(v);
}

/// Asks for huge pages over the room of `v` past its elements, when that
/// spans at least two of them.
fn advise<T>(v: &Vec<T>) {
    let size = std::mem::size_of::<T>();
    if v.capacity().saturating_sub(v.len()).saturating_mul(size) < 2 * HUGE {
        return;
    }
    #[cfg(target_os = "linux")]
    {
        let start = v.as_ptr() as usize + v.len() * size;
        let aligned = (start + HUGE - 1) & !(HUGE - 1);
        let end = (v.as_ptr() as usize + v.capacity() * size) & !(HUGE - 1);
        if end > aligned {
            // SAFETY: the range lies inside `v`'s own allocation, past its
            // elements, and MADV_HUGEPAGE never changes memory's contents;
            // a failure leaves ordinary pages.
            unsafe {
                libc::madvise(
                    aligned as *mut libc::c_void,
                    end - aligned,
                    libc::MADV_HUGEPAGE,
                );
            }
        }
    }
}

/// Makes the allocator give freed memory back to the system promptly, for
/// the rest of the process: a command that builds one large mesh calls it
/// first. glibc raises its threshold for `mmap` (to 32 MiB at most) as
/// blocks under it are freed, and its trim threshold to twice that; after
/// that the medium buffers a subdivision step makes and frees (match
/// lists in the worker threads, point batches) come from heaps whose free
/// top stays resident until 64 MiB lie there: tens of megabytes under
/// the step's largest buffer (about 40 MB at three levels of Loop on 81,920
/// triangles). Setting the threshold keeps it at glibc's initial 128 KiB
/// and stops the raising, so larger blocks are mapped and unmapped and the
/// heaps are trimmed as they free. Long-lived processes that reuse medium
/// buffers (the word of a derivation) keep the default.
pub(crate) fn return_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt changes only when the allocator maps and unmaps
    // memory; it may be called at any time.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 << 10);
    }
}
