//! Large output arrays and the kernel's transparent huge pages.
//!
//! A level-3 refinement of a 100k-face mesh writes several hundred megabytes into freshly
//! allocated arrays. With 4 KiB pages, Linux takes a page fault and clears a page for every
//! 4 KiB first written; on the benchmark machine that was about a third of the refinement's
//! time, and it does not get faster with more threads (the faults serialise in the kernel).
//! Arrays of [`HUGE_PAGE_MIN_BYTES`] and more are therefore advised with
//! `madvise(MADV_HUGEPAGE)` before their first write: the kernel then backs them with 2 MiB
//! pages where it can, one fault per 2 MiB instead of 512.
//!
//! The advice changes only the page size the kernel picks for memory this crate owns; it does
//! not change contents, and it is ignored where transparent huge pages are switched off
//! (`/sys/kernel/mm/transparent_hugepage/enabled` = `never`). It is a no-op on other systems.
//! [`set_huge_pages`] turns it off for the whole process.

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use rayon::iter::ParallelExtend;

/// Arrays smaller than this are allocated normally (less than two huge pages gain nothing).
pub const HUGE_PAGE_MIN_BYTES: usize = 4 << 20;

static HUGE_PAGES: AtomicBool = AtomicBool::new(true);

/// Turns the huge-page advice for large refinement arrays on (the default) or off, for the
/// whole process.
///
/// ```
/// subd_mesh::memory::set_huge_pages(false);
/// assert!(!subd_mesh::memory::huge_pages());
/// subd_mesh::memory::set_huge_pages(true);
/// ```
pub fn set_huge_pages(enabled: bool) {
    HUGE_PAGES.store(enabled, Ordering::Relaxed);
}

/// Keeps memory the process frees for its next allocations instead of handing it back to
/// the kernel (glibc's `mallopt`: blocks up to 32 MiB come from the heap, which is trimmed
/// only past 1 GiB free). For work that allocates and frees the same large arrays over and
/// over (depth-first refinement, chunk after chunk): a page handed back is faulted in and
/// cleared again on its next use, which cost more than a third of the run's system time.
/// The peak does not grow: freed memory is reused before any more is asked for. A no-op
/// where the C library is not glibc.
pub fn reuse_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    #[allow(unsafe_code)]
    // SAFETY: mallopt only sets allocator thresholds; it is safe to call at any time, from
    // any thread, and a rejected value leaves the setting as it was.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 30);
    }
}

/// Whether large refinement arrays are advised to use huge pages.
pub fn huge_pages() -> bool {
    HUGE_PAGES.load(Ordering::Relaxed)
}

/// Whether `bytes` can be allocated now: reserves them (address space only, no page is
/// touched) and gives them back. Under an address-space limit (`ulimit -v`) or a strict
/// overcommit policy this is where a too-large request shows, as a value instead of an
/// abort in the middle of filling an array.
///
/// ```
/// assert!(subd_mesh::memory::can_allocate(1 << 20));
/// assert!(!subd_mesh::memory::can_allocate(u64::MAX));
/// ```
pub fn can_allocate(bytes: u64) -> bool {
    let Ok(n) = usize::try_from(bytes) else {
        return false;
    };
    Vec::<u8>::new().try_reserve_exact(n).is_ok()
}

/// `bytes` for people: `512 B`, `3.2 MiB`, `1.5 GiB`.
///
/// ```
/// assert_eq!(subd_mesh::memory::human_bytes(3 << 29), "1.5 GiB");
/// ```
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} B")
    } else {
        format!("{v:.1} {}", UNITS[unit])
    }
}

/// A zeroed vector of `len` elements; large ones are advised to use huge pages before anything
/// touches them.
///
/// The large case allocates without zeroing, advises, and then zeroes: `calloc` would clear
/// memory it reuses from the heap before the advice could take effect, taking 4 KiB faults.
///
/// ```
/// let v: Vec<f64> = subd_mesh::memory::zeroed(1 << 20);
/// assert!(v.len() == 1 << 20 && v.iter().all(|&x| x == 0.0));
/// ```
pub fn zeroed<T: bytemuck::Zeroable + Clone + Send + Sync>(len: usize) -> Vec<T> {
    let bytes = len.saturating_mul(std::mem::size_of::<T>());
    if !huge_pages() || bytes < HUGE_PAGE_MIN_BYTES {
        return bytemuck::allocation::zeroed_vec(len);
    }
    let mut v = with_capacity(len);
    // Zeroed by all threads, so the first touch of the pages is spread like the writes after.
    v.par_extend(rayon::iter::repeat_n(T::zeroed(), len));
    v
}

/// An empty vector with room for `len` elements, its memory advised to use huge pages when
/// large; for filling with `par_extend`, which writes every element once, in place.
pub fn with_capacity<T>(len: usize) -> Vec<T> {
    let v: Vec<T> = Vec::with_capacity(len);
    let bytes = len.saturating_mul(std::mem::size_of::<T>());
    if huge_pages() && bytes >= HUGE_PAGE_MIN_BYTES {
        advise_huge(v.as_ptr().cast(), bytes);
    }
    v
}

/// A vector of `len` elements written once, in place, in parallel: first every index in
/// `middle` by `first(i)`, then every other index by `rest(i, m)`, where `m` is the finished
/// `middle` part (index `i` of `m` is element `middle.start + i`). For arrays whose later
/// elements read a block in the middle (child vertex points read the face points), without a
/// scratch copy of that block and without zeroing the array first. Large arrays get the
/// huge-page advice.
///
/// # Panics
/// If `middle` does not lie within `0..len` (before anything is written).
pub fn build_around<T, F, R>(
    len: usize,
    middle: std::ops::Range<usize>,
    min_chunk: usize,
    first: F,
    rest: R,
) -> Vec<T>
where
    T: Copy + Send + Sync,
    F: Fn(usize) -> T + Sync,
    R: Fn(usize, &[T]) -> T + Sync,
{
    use rayon::prelude::*;
    assert!(middle.start <= middle.end && middle.end <= len);
    let mut v: Vec<T> = with_capacity(len);
    let spare = &mut v.spare_capacity_mut()[..len];
    let (head, tail) = spare.split_at_mut(middle.start);
    let (mid, tail) = tail.split_at_mut(middle.end - middle.start);
    mid.par_iter_mut()
        .with_min_len(min_chunk)
        .enumerate()
        .for_each(|(i, o)| {
            o.write(first(middle.start + i));
        });
    #[allow(unsafe_code)]
    // SAFETY: every element of `mid` was written just above (the loop visits each once), so
    // viewing it as initialised `T` is sound; `MaybeUninit<T>` has `T`'s layout.
    let mid: &[T] = unsafe { std::slice::from_raw_parts(mid.as_ptr().cast::<T>(), mid.len()) };
    head.par_iter_mut()
        .with_min_len(min_chunk)
        .enumerate()
        .for_each(|(i, o)| {
            o.write(rest(i, mid));
        });
    tail.par_iter_mut()
        .with_min_len(min_chunk)
        .enumerate()
        .for_each(|(i, o)| {
            o.write(rest(middle.end + i, mid));
        });
    #[allow(unsafe_code)]
    // SAFETY: the three loops above wrote every index of `0..len` (head, middle and tail
    // partition it), and `len` is within the capacity reserved by `with_capacity`. A panic in
    // a closure unwinds before this point, leaving the length 0 (`T: Copy` needs no drop).
    unsafe {
        v.set_len(len)
    };
    v
}

/// A vector of `len` atomics, element `i` set to `init(i)` in parallel: an array that
/// parallel tasks fill at scattered, disjoint places (relaxed stores compile to plain ones).
/// Large ones get the huge-page advice.
pub(crate) fn atomic_u32s(len: usize, init: impl Fn(usize) -> u32 + Sync) -> Vec<AtomicU32> {
    use rayon::prelude::*;
    let mut v = with_capacity(len);
    v.par_extend((0..len).into_par_iter().map(|i| AtomicU32::new(init(i))));
    v
}

/// The values of `atomics`, in place: no copy, no pass over the array.
pub(crate) fn into_u32s(atomics: Vec<AtomicU32>) -> Vec<u32> {
    let mut atomics = std::mem::ManuallyDrop::new(atomics);
    let (ptr, len, capacity) = (atomics.as_mut_ptr(), atomics.len(), atomics.capacity());
    #[allow(unsafe_code)]
    // SAFETY: `AtomicU32` has the size, alignment and bit validity of `u32` (its documented
    // guarantee), so the allocation, its length and capacity describe a valid `Vec<u32>`
    // with the same layout; the original vector is not dropped (`ManuallyDrop`), so the
    // allocation has exactly one owner.
    unsafe {
        Vec::from_raw_parts(ptr.cast::<u32>(), len, capacity)
    }
}

/// Advises the kernel to back the 2 MiB-aligned interior of `[start, start + bytes)` with
/// huge pages.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
fn advise_huge(start: *const u8, bytes: usize) {
    const HUGE: usize = 2 << 20;
    let first = (start as usize).next_multiple_of(HUGE);
    let end = (start as usize + bytes) / HUGE * HUGE;
    if end > first {
        // SAFETY: the range lies inside one live allocation owned by the caller, and
        // MADV_HUGEPAGE only sets the page-size policy of its mapping: no memory is freed,
        // moved or changed. A failure (e.g. THP compiled out) leaves the mapping as it was,
        // so the result is deliberately ignored.
        unsafe {
            libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge(_start: *const u8, _bytes: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn build_around_writes_every_element_from_its_closure() {
        for (len, middle) in [
            (0usize, 0..0),
            (10, 3..7),
            (10, 0..10),
            (300_000, 100_000..150_000),
        ] {
            let m0 = middle.start;
            let v = build_around(
                len,
                middle.clone(),
                1000,
                |i| i as u64 * 3,
                |i, mid: &[u64]| {
                    // The middle block is complete when the rest is written.
                    assert_eq!(mid.len(), middle.len());
                    assert!(
                        mid.iter()
                            .enumerate()
                            .take(3)
                            .all(|(k, &x)| x == (m0 + k) as u64 * 3)
                    );
                    i as u64 * 5
                },
            );
            assert_eq!(v.len(), len);
            for (i, &x) in v.iter().enumerate() {
                let want = if middle.contains(&i) { 3 * i } else { 5 * i };
                assert_eq!(x, want as u64);
            }
        }
    }

    #[test]
    fn atomics_become_their_values() {
        for len in [0usize, 3, HUGE_PAGE_MIN_BYTES / 4 + 7] {
            let a = atomic_u32s(len, |i| i as u32 * 7);
            if let Some(x) = a.last() {
                x.store(1, Ordering::Relaxed);
            }
            let v = into_u32s(a);
            assert_eq!(v.len(), len);
            let want = |i: usize| if i + 1 == len { 1 } else { i as u32 * 7 };
            assert!(v.iter().enumerate().all(|(i, &x)| x == want(i)));
        }
    }

    #[test]
    fn large_and_small_vectors_are_zeroed() {
        for len in [0usize, 1, 1000, HUGE_PAGE_MIN_BYTES / 4 + 12345] {
            let v: Vec<u32> = zeroed(len);
            assert_eq!(v.len(), len);
            assert!(v.iter().all(|&x| x == 0));
        }
    }
}
