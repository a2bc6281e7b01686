//! Keeping freed memory in the process.
//!
//! A training step allocates and frees hundreds of tensors of several megabytes. glibc's
//! allocator hands blocks that large back to the kernel on every free, so each new tensor
//! costs page faults and page clearing, a large share of a step at the paper size; keeping freed
//! memory in the heap removes that (docs/PERFORMANCE.md).

/// Tells the C allocator to serve large blocks from the heap and not to give freed memory back.
/// Call once at start-up, before tensors are made. A no-op outside glibc.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes allocator tuning parameters; it is called before any other
    // thread exists and takes plain integer arguments.
    unsafe {
        libc::mallopt(libc::M_MMAP_MAX, 0);
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
        libc::mallopt(libc::M_TOP_PAD, 256 << 20);
    }
}
