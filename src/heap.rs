//! Hints to glibc's allocator while a scene loads.
//!
//! A load of a million triangles allocates and frees a dozen arrays of
//! 30–150 MB in turn (the triangle list, the packed arrays, PLOC's buffers,
//! the wide nodes, the arrays in leaf order). glibc serves each of them
//! from a fresh mapping and unmaps it when freed, so every array's pages
//! are faulted in anew: 185 000 faults on the kitchen, about 2.5 µs each,
//! PLOC's alone costing it 0.09 s of its 0.2. From the heap instead, a new
//! array reuses the pages the last one left. Freed pages then stay in the
//! process until trimmed, so the builder returns them where an array it
//! no longer needs would otherwise be held through the peak
//! (docs/performance.md, "Loading and memory"). Elsewhere than glibc these
//! are no-ops.

/// While alive, large allocations come from the heap, not fresh mappings;
/// dropped, the thresholds are left as glibc's own would be after a large
/// load, and the free pages go back to the system.
/// The setting is the process's: a load that ends first restores it for
/// one still running, which then only loads as before.
pub struct HeapReuse(());

impl HeapReuse {
    #[must_use = "the thresholds are reset when this is dropped"]
    pub fn begin() -> HeapReuse {
        // Above any one array of the largest scene allowed; the trim
        // threshold glibc's default, as measured (the explicit trims
        // return what the peak must not hold).
        set_thresholds(1 << 30, 128 << 10);
        HeapReuse(())
    }
}

impl Drop for HeapReuse {
    fn drop(&mut self) {
        // Where glibc's own thresholds end after a large block is freed
        // (the mmap threshold rises to at most 32 MiB, the trim threshold
        // to twice that); once set they no longer adapt, and a fixed
        // 128 KiB would map and fault every later buffer above it anew.
        set_thresholds(32 << 20, 64 << 20);
        release_free_pages();
    }
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
unsafe extern "C" {
    fn malloc_trim(pad: usize) -> std::ffi::c_int;
    fn mallopt(param: std::ffi::c_int, value: std::ffi::c_int) -> std::ffi::c_int;
}

/// glibc's mmap and trim thresholds, in bytes.
fn set_thresholds(mmap: i32, trim: i32) {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        const M_TRIM_THRESHOLD: std::ffi::c_int = -1;
        const M_MMAP_THRESHOLD: std::ffi::c_int = -3;
        // SAFETY: mallopt only changes tuning parameters under the
        // allocator's lock; no allocation is touched.
        unsafe {
            mallopt(M_MMAP_THRESHOLD, mmap);
            mallopt(M_TRIM_THRESHOLD, trim);
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let _ = (mmap, trim);
}

/// Returns the free pages of every arena to the system: memory freed on
/// worker threads stays in their arenas, and freed heap memory below a live
/// block stays in the process, where the next arrays may not fit it.
pub fn release_free_pages() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: glibc's malloc_trim only returns free pages of its arenas
    // to the system; it touches no live allocation.
    unsafe {
        malloc_trim(0);
    }
}
