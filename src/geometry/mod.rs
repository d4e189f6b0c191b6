//! Rays, shapes, transforms and the acceleration structures that find what a ray hits.

pub mod aabb;
pub mod bvh;
pub mod generate;
pub mod lanes;
pub mod mesh;
pub mod obj;
pub mod plane;
pub mod ray;
pub mod spawn;
pub mod sphere;
pub mod transform;
pub mod triangle;

pub use ray::{Ray, SurfaceHit};

/// An empty vector with room for `capacity` elements whose memory the kernel may back with
/// 2 MiB pages (Linux transparent huge pages, asked for with `madvise`, as Embree does). Large
/// trees are traversed in an order no cache predicts, and with 4 KiB pages nearly every node a
/// ray visits also misses the TLB. Only a hint: nothing changes but how memory is mapped.
pub(crate) fn huge_page_vec<T>(capacity: usize) -> Vec<T> {
    let mut vec = Vec::with_capacity(capacity);
    #[cfg(target_os = "linux")]
    {
        const HUGE_PAGE: usize = 2 << 20;
        let (start, bytes) = (vec.as_mut_ptr() as usize, capacity * size_of::<T>());
        let (first, end) = (start.next_multiple_of(HUGE_PAGE), (start + bytes) & !(HUGE_PAGE - 1));
        if end > first {
            // SAFETY: the range lies inside the vector's allocation, which is not yet written;
            // MADV_HUGEPAGE changes how it is mapped, never its contents.
            unsafe { libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE) };
        }
    }
    vec
}

use super::real;
