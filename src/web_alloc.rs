//! The threaded page's allocator: small blocks cached per thread in front of the standard one.
//!
//! In a WebAssembly build with atomics, Rust's allocator (dlmalloc) is one spin lock for every
//! thread. The page's threads share two or more cores with the browser's own (the rasterizer
//! among them), so a thread that holds the lock can be taken off its core while the others spin
//! for it: a STEP read, which allocates for every instance it parses and every edge it builds,
//! took three times as long on two threads as on one. Here each thread keeps the blocks of up
//! to 4 KB it frees in lists by size (powers of two from 16 bytes), and takes a block of the
//! size it asks for from its own list first, without the lock. A list holds at most
//! [`CACHED_BYTES`]; beyond that, and for larger blocks, the standard allocator serves.
//! A block freed on another thread than the one that made it joins the freeing thread's list.
//! A thread's cached blocks are not given back when it ends: the page's threads live as long
//! as the page.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ptr::null_mut;

/// The size classes: 16, 32, …, 4096 bytes.
const CLASSES: usize = 9;
const SMALLEST: usize = 16;
/// The bytes one thread keeps cached in one size class.
const CACHED_BYTES: usize = 1 << 20;

/// One thread's free blocks: for each class the first (each block holds the address of the
/// next) and how many.
struct Cache {
    first: [Cell<*mut u8>; CLASSES],
    count: [Cell<usize>; CLASSES],
}

thread_local! {
    static CACHE: Cache = const {
        Cache {
            first: [const { Cell::new(null_mut()) }; CLASSES],
            count: [const { Cell::new(0) }; CLASSES],
        }
    };
}

/// The class of blocks that serves `layout`, if it is small (and aligned to at most 16).
fn class_of(layout: Layout) -> Option<usize> {
    let size = layout.size().max(SMALLEST).next_power_of_two();
    let class = (size / SMALLEST).trailing_zeros() as usize;
    (class < CLASSES && layout.align() <= SMALLEST).then_some(class)
}

/// A block of class `class` as the standard allocator is asked for it.
fn block_layout(class: usize) -> Layout {
    // SAFETY: a power of two from 16 to 4096, aligned to 16.
    unsafe { Layout::from_size_align_unchecked(SMALLEST << class, SMALLEST) }
}

/// The allocator: [`System`] behind per-thread lists of small blocks.
pub struct ThreadCaching;

// SAFETY: every block handed out is one the standard allocator made for its class's size and
// alignment (which serve every layout of the class); a cached block is used by one thread at a
// time, being in one thread's list until taken from it.
unsafe impl GlobalAlloc for ThreadCaching {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let Some(class) = class_of(layout) else {
            return unsafe { System.alloc(layout) };
        };
        let cached = CACHE
            .try_with(|cache| {
                let block = cache.first[class].get();
                if !block.is_null() {
                    // SAFETY: a cached block holds the address of the next one.
                    cache.first[class].set(unsafe { block.cast::<*mut u8>().read() });
                    cache.count[class].set(cache.count[class].get() - 1);
                }
                block
            })
            .unwrap_or(null_mut());
        if cached.is_null() {
            unsafe { System.alloc(block_layout(class)) }
        } else {
            cached
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        let Some(class) = class_of(layout) else {
            return unsafe { System.dealloc(ptr, layout) };
        };
        let kept = CACHE
            .try_with(|cache| {
                let count = cache.count[class].get();
                if count >= CACHED_BYTES >> (class + 4) {
                    return false;
                }
                // SAFETY: the block is at least 16 bytes, aligned to 16, and no longer used.
                unsafe { ptr.cast::<*mut u8>().write(cache.first[class].get()) };
                cache.first[class].set(ptr);
                cache.count[class].set(count + 1);
                true
            })
            .unwrap_or(false);
        if !kept {
            unsafe { System.dealloc(ptr, block_layout(class)) }
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller promises a valid size for the old alignment.
        let new_layout = unsafe { Layout::from_size_align_unchecked(new_size, layout.align()) };
        match (class_of(layout), class_of(new_layout)) {
            (Some(old), Some(new)) if old == new => ptr,
            (None, None) => unsafe { System.realloc(ptr, layout, new_size) },
            _ => {
                let moved = unsafe { self.alloc(new_layout) };
                if !moved.is_null() {
                    unsafe {
                        std::ptr::copy_nonoverlapping(ptr, moved, layout.size().min(new_size));
                        self.dealloc(ptr, layout);
                    }
                }
                moved
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block the test holds: its address, layout and the byte it is filled with.
    type Held = (usize, Layout, u8);

    fn filled(ptr: *mut u8, layout: Layout, byte: u8) -> bool {
        // SAFETY: `ptr` is a live block of `layout`.
        unsafe { std::slice::from_raw_parts(ptr, layout.size()) }
            .iter()
            .all(|&b| b == byte)
    }

    #[test]
    fn blocks_of_any_size_stay_whole_aligned_and_go_back_from_any_thread() {
        let a = &ThreadCaching;
        let held: Vec<Vec<Held>> = std::thread::scope(|scope| {
            let workers: Vec<_> = (0..4u64)
                .map(|t| {
                    scope.spawn(move || {
                        let mut state = 0x9e37_79b9_7f4a_7c15 ^ t;
                        let mut next = move |n: u64| {
                            state ^= state << 13;
                            state ^= state >> 7;
                            state ^= state << 17;
                            state % n
                        };
                        let mut held: Vec<Held> = Vec::new();
                        for step in 0..20_000u32 {
                            let byte = (step % 251) as u8;
                            let size = 1 + next(6000) as usize;
                            let align = 1usize << next(6);
                            let layout = Layout::from_size_align(size, align).unwrap();
                            let ptr = unsafe { a.alloc(layout) };
                            assert!(!ptr.is_null() && (ptr as usize).is_multiple_of(align));
                            unsafe { ptr.write_bytes(byte, size) };
                            held.push((ptr as usize, layout, byte));
                            match next(4) {
                                0 => {
                                    let (ptr, layout, byte) =
                                        held.swap_remove(next(held.len() as u64) as usize);
                                    assert!(filled(ptr as *mut u8, layout, byte));
                                    unsafe { a.dealloc(ptr as *mut u8, layout) };
                                }
                                1 => {
                                    let k = next(held.len() as u64) as usize;
                                    let (ptr, layout, byte) = held[k];
                                    let size = 1 + next(6000) as usize;
                                    let moved = unsafe { a.realloc(ptr as *mut u8, layout, size) };
                                    let layout =
                                        Layout::from_size_align(size, layout.align()).unwrap();
                                    assert!(
                                        !moved.is_null()
                                            && (moved as usize).is_multiple_of(layout.align())
                                    );
                                    let kept = size.min(held[k].1.size());
                                    let prefix = Layout::from_size_align(kept, 1).unwrap();
                                    assert!(filled(moved, prefix, byte), "a realloc lost bytes");
                                    unsafe { moved.write_bytes(byte, size) };
                                    held[k] = (moved as usize, layout, byte);
                                }
                                _ => {}
                            }
                        }
                        held
                    })
                })
                .collect();
            workers.into_iter().map(|w| w.join().unwrap()).collect()
        });
        // Freed on this thread, not the ones that made them.
        for (ptr, layout, byte) in held.into_iter().flatten() {
            assert!(
                filled(ptr as *mut u8, layout, byte),
                "a block was overwritten"
            );
            unsafe { a.dealloc(ptr as *mut u8, layout) };
        }
        assert_eq!(
            class_of(Layout::from_size_align(4096, 16).unwrap()),
            Some(8)
        );
        assert_eq!(class_of(Layout::from_size_align(4097, 16).unwrap()), None);
        assert_eq!(class_of(Layout::from_size_align(8, 32).unwrap()), None);
        assert_eq!(class_of(Layout::from_size_align(17, 8).unwrap()), Some(1));
    }
}
