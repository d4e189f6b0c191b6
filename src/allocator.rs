//! The process's allocator: the system's, with the memory of large blocks backed by transparent
//! huge pages where the kernel offers them.
//!
//! A render's film, a cube map's decoded faces and a picture's bytes are blocks of megabytes
//! that are written once, page by page, soon after they are allocated. With 4 KiB pages each
//! first write of a page is a page fault: an 800×800 render of the course's scenes took 5,000 to
//! 8,000 of them, and the kernel's work on them (and on unmapping them at exit) was a fifth of a
//! one-sample render's processor time. A block advised `MADV_HUGEPAGE` is filled 2 MiB at a
//! time instead: the course's seven commands went from 369–382 to 326–354 ms of wall time
//! (`docs/speed.md`). This is what glibc's `glibc.malloc.hugetlb=1` tunable does, which a
//! program cannot set for itself; it stays within the kernel's policy
//! (`/sys/kernel/mm/transparent_hugepage/enabled`): with `never` the advice changes nothing.
//! Only whole huge pages inside a block are advised, so no other block shares one.

// The heap's advice needs glibc's heap; elsewhere only blocks are advised and the heap's part
// is compiled but unused.
#![cfg_attr(not(all(target_os = "linux", target_env = "gnu")), allow(dead_code, unused_imports))]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The size of a transparent huge page on x86-64 and of the usual aarch64 configuration.
const HUGE_PAGE: usize = 2 << 20;

/// Blocks from this size up look whether the heap grew (see [`advise_heap_growth`]).
const LARGE_BLOCK: usize = 64 << 10;

/// Up to where the heap is advised to use huge pages; 0 until the first large block.
static HEAP_ADVISED_UP_TO: AtomicUsize = AtomicUsize::new(0);

/// How much of the heap, from the first large block, is advised to use huge pages. A render's
/// heap (40–60 MB for the course's scenes at 800×800) is written once, soon after it grows,
/// where huge pages save most of the page faults; a grading's grows to a gigabyte that is
/// filled, freed and reused, where zeroing whole huge pages of fresh memory cost more than the
/// faults it saved (a diagnosed grading of 20 students: system time 0.7 -> 0.9-1.3 s).
const HEAP_ADVISED_LIMIT: usize = 128 << 20;

/// Where the heap's advice began (the first large block's address); 0 until then.
static HEAP_ADVISED_FROM: AtomicUsize = AtomicUsize::new(0);

/// [`System`], advising every block that holds a whole huge page, and the heap as it grows,
/// to be backed by huge pages.
pub struct HugePageBlocks;

// SAFETY: every block comes from `System` and goes back to it with the same layout; the advice
// only changes how the kernel backs memory the block owns, never its contents.
unsafe impl GlobalAlloc for HugePageBlocks {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract for `alloc`, passed on.
        let block = unsafe { System.alloc(layout) };
        advise_large_block(block, layout.size());
        block
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract for `alloc_zeroed`, passed on.
        let block = unsafe { System.alloc_zeroed(layout) };
        advise_large_block(block, layout.size());
        block
    }

    unsafe fn dealloc(&self, block: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract for `dealloc`, passed on; the block came from `System`.
        unsafe { System.dealloc(block, layout) }
    }

    unsafe fn realloc(&self, block: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract for `realloc`, passed on; the block came from `System`.
        let grown = unsafe { System.realloc(block, layout, new_size) };
        if new_size > layout.size() {
            advise_large_block(grown, new_size);
        }
        grown
    }
}

/// The whole huge pages inside `size` bytes from `block`, as a start address and a length.
fn whole_huge_pages(block: usize, size: usize) -> Option<(usize, usize)> {
    let start = block.checked_next_multiple_of(HUGE_PAGE)?;
    let end = block.checked_add(size)? / HUGE_PAGE * HUGE_PAGE;
    (end > start).then(|| (start, end - start))
}

/// Advises huge pages for a large block: for the heap's growth when it comes from glibc's heap,
/// for its own whole huge pages otherwise. glibc gives the blocks under its mmap threshold (32
/// MB, see the command line's `keep_freed_memory`) from one heap that grows at its top; the
/// advice of the heap's new range covers them and the smaller blocks carved from it too (rows,
/// a PNG's chunks). A block reused from freed heap memory asks for nothing: advising each one
/// again took the address space's lock thousands of times in a diagnosed grading, against every
/// other thread's page faults (system time 0.65 -> 1.4-2.1 s).
fn advise_large_block(block: *mut u8, size: usize) {
    if block.is_null() || size < LARGE_BLOCK || advise_heap_growth(block as usize) {
        return;
    }
    if let Some((start, length)) = whole_huge_pages(block as usize, size) {
        advise_huge_pages(start, length);
    }
}

/// Advises huge pages for the heap from where it was last advised (or, the first time, from
/// `block`) up to its current top, when `block` lies in the heap; whether it does.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn advise_heap_growth(block: usize) -> bool {
    // SAFETY: sbrk(0) only reads the current program break.
    let top = unsafe { libc::sbrk(0) } as usize;
    if block >= top {
        return false;
    }
    let from = match HEAP_ADVISED_FROM.compare_exchange(0, block, Ordering::Relaxed, Ordering::Relaxed) {
        Ok(_) => block,
        Err(from) => from,
    };
    let top = top.min(from.saturating_add(HEAP_ADVISED_LIMIT));
    if let Some((start, length)) = heap_to_advise(HEAP_ADVISED_UP_TO.load(Ordering::Relaxed), block, top)
        && HEAP_ADVISED_UP_TO.fetch_max(start + length, Ordering::Relaxed) < start + length
    {
        advise_huge_pages(start, length);
    }
    true
}

/// The whole huge pages of the heap not advised yet, when it is advised up to `advised` (0 for
/// not yet), has its top at `top` and has just given `block`; `None` when `block` is not from
/// the heap (a mapping of its own lies above the heap's top) or no whole huge page is new.
fn heap_to_advise(advised: usize, block: usize, top: usize) -> Option<(usize, usize)> {
    if block >= top {
        return None;
    }
    let from = if advised == 0 { block } else { advised };
    whole_huge_pages(from, top.checked_sub(from)?)
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn advise_heap_growth(_block: usize) -> bool {
    false
}

/// How much glibc's heap grows beyond a block that does not fit.
const HEAP_STEP: usize = 64 << 20;

/// Makes glibc's heap grow [`HEAP_STEP`] at a time, and grows it once now, so that the heap's
/// memory is advised to use huge pages (see [`advise_heap_growth`]) before blocks are carved
/// from it and written: grown by each block's size only, a block's pages were written by
/// `calloc`'s zeroing, in 4 KiB pages, before the advice could cover them (an 800×800 render
/// of the course's scene 1 kept 2,500 of its 5,900 page faults). Memory never written costs
/// nothing. Call it before any thread starts.
pub fn grow_heap_in_large_steps() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallopt only sets an allocator parameter; no other thread runs yet.
        unsafe {
            libc::mallopt(libc::M_TOP_PAD, HEAP_STEP as libc::c_int);
        }
        // More than the free space at the top of the heap that the runtime's start made (glibc's
        // default pad, 128 KiB), so the heap grows now, by a step.
        drop(std::hint::black_box(Vec::<u8>::with_capacity(1 << 20)));
    }
}

/// Advises the kernel to back `length` bytes from `start` with huge pages. Failure is harmless
/// (a kernel without transparent huge pages refuses the advice) and ignored.
fn advise_huge_pages(start: usize, length: usize) {
    #[cfg(target_os = "linux")]
    // SAFETY: the range lies inside a block this allocator handed out or inside the heap below
    // its top, so it is mapped; MADV_HUGEPAGE changes how it is backed, never what it holds.
    unsafe {
        libc::madvise(start as *mut libc::c_void, length, libc::MADV_HUGEPAGE);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (start, length);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_whole_huge_pages_inside_the_block_are_advised() {
        let mib = 1 << 20;
        assert_eq!(whole_huge_pages(0, 4 * mib), Some((0, 4 * mib)));
        assert_eq!(whole_huge_pages(16, 4 * mib), Some((2 * mib, 2 * mib)));
        assert_eq!(whole_huge_pages(mib, 4 * mib), Some((2 * mib, 2 * mib)));
        assert_eq!(whole_huge_pages(16, 3 * mib), None);
        assert_eq!(whole_huge_pages(2 * mib, 2 * mib - 1), None);
        assert_eq!(whole_huge_pages(usize::MAX - mib, 4 * mib), None);
    }

    #[test]
    fn the_heap_is_advised_once_from_its_first_large_block_to_its_top() {
        let mib = 1 << 20;
        assert_eq!(heap_to_advise(0, 3 * mib, 70 * mib), Some((4 * mib, 66 * mib)));
        assert_eq!(
            heap_to_advise(70 * mib, 80 * mib, 140 * mib),
            Some((70 * mib, 70 * mib))
        );
        assert_eq!(heap_to_advise(70 * mib, 20 * mib, 71 * mib), None, "nothing new");
        assert_eq!(heap_to_advise(70 * mib, 20 * mib, 60 * mib), None, "the heap shrank");
        assert_eq!(
            heap_to_advise(70 * mib, 900 * mib, 140 * mib),
            None,
            "a mapping of its own"
        );
    }

    /// The VmFlags of the mapping that holds `address`, from /proc/self/smaps.
    #[cfg(target_os = "linux")]
    fn mapping_flags(address: usize) -> String {
        let smaps = std::fs::read_to_string("/proc/self/smaps").expect("/proc/self/smaps is readable");
        let mut inside = false;
        for line in smaps.lines() {
            let first = line.split_whitespace().next().unwrap_or("");
            if let Some((low, high)) = first.split_once('-')
                && let (Ok(low), Ok(high)) = (usize::from_str_radix(low, 16), usize::from_str_radix(high, 16))
            {
                inside = (low..high).contains(&address);
            } else if inside && let Some(flags) = line.strip_prefix("VmFlags:") {
                return flags.to_string();
            }
        }
        panic!("no mapping holds {address:#x}");
    }

    /// A large block through the allocator is marked for huge pages (the `hg` flag of its
    /// mapping) wherever the kernel has transparent huge pages; its bytes are the caller's.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_large_block_is_advised_to_use_huge_pages() {
        let mut block = vec![0u8; 8 << 20];
        let (start, _) = whole_huge_pages(block.as_ptr() as usize, block.len()).expect("8 MiB holds a huge page");
        let base = block.as_ptr() as usize;
        block[start - base] = 7;
        assert_eq!(block.iter().map(|&b| b as usize).sum::<usize>(), 7);
        let policy = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled").unwrap_or_default();
        if policy.contains("[madvise]") || policy.contains("[always]") {
            let flags = mapping_flags(start);
            assert!(
                flags.split_whitespace().any(|flag| flag == "hg"),
                "VmFlags of the block: {flags}"
            );
        }
    }
}
