//! The C allocator's settings for a short process that touches each fresh
//! page once (`hydrocyl simulate`): on this kind of host a first touch of a
//! page costs ~2.5 µs, so memory freed by one phase (the command file's
//! bytes, the parse's halves) is better reused by the next (the output's
//! blocks and texts) than handed back to the kernel and faulted in afresh.
//! The crate's one use of `unsafe`: a call into the C library.
#![allow(unsafe_code)]

/// Keeps freed memory in the process for reuse, on glibc: no `mmap` for
/// allocations below 32 MiB (an `mmap`ed buffer, glibc's default above
/// 128 KiB, goes back to the kernel when freed, and the next is faulted in
/// afresh) and no trimming of the heap's top. The threads keep their own arenas: one arena for all (fewer
/// faults still) was no faster. Called before the
/// process's other threads start; elsewhere (another C library) it does
/// nothing.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes the allocator's parameters; it takes the
    // allocator's lock and may be called at any time.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
    }
}
