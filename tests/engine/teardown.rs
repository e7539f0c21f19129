//! RAII in the renderer: constructing, rendering with and tearing down a [`Renderer`] gives
//! back everything it took: gpu-allocator's allocations return to zero, and so do the Rust
//! heap bytes this thread holds (a field that `into_context` forgot to drop leaks its `Vec`s),
//! after a successful construction; gpu-allocator's also after one failed at each of its
//! allocations in turn.
use crate::common;
use ash::vk;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use umbrage::gpu::fault::{set_thread_faults, Fault, FaultPoint};
use umbrage::gpu::Context;
use umbrage_render::{NewError, RenderOptions, Renderer};

/// The system allocator, counting the bytes each thread holds (allocated minus freed there).
struct Counting;

thread_local! {
    static HELD: Cell<i64> = const { Cell::new(0) };
}

// SAFETY: forwards to `System`; the count is a thread-local `Cell` without a destructor, so
// counting neither allocates nor re-enters the allocator.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract, forwarded.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let _ = HELD.try_with(|h| h.set(h.get() + layout.size() as i64));
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        let _ = HELD.try_with(|h| h.set(h.get() - layout.size() as i64));
        // SAFETY: the caller's contract, forwarded.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

fn heap_held() -> i64 {
    HELD.with(Cell::get)
}

/// gpu-allocator's live allocations and their bytes.
fn gpu_allocations(ctx: &Context) -> (usize, u64) {
    let r = ctx.allocator().generate_report();
    (r.allocations.len(), r.total_allocated_bytes)
}

/// Transparent casters (self-shadowing on), an opaque box, a sphere: every part of the
/// renderer is made.
const SCENE: &str = r#"
name = "teardown"
[camera]
eye = [6.0, 3.0, 6.0]
target = [0.0, 1.0, 0.0]
[[light]]
kind = "point"
position = [0.0, 8.0, 0.0]
[[mesh]]
name = "floor"
shape = "plane"
casts_shadow = false
size = [14.0, 14.0]
[[mesh]]
name = "box"
shape = "box"
size = [0.6, 0.6, 0.6]
translate = [2.5, 0.3, -1.5]
[[mesh]]
name = "slab"
shape = "box"
size = [3.0, 0.2, 3.0]
translate = [0.0, 1.0, 0.0]
opacity = 0.4
[[sphere]]
center = [-2.0, 1.0, 1.0]
radius = 0.5
"#;

fn scene() -> umbrage_scene::Scene {
    umbrage_scene::load_str(SCENE, "teardown", std::path::Path::new(".")).unwrap()
}

fn options() -> RenderOptions {
    RenderOptions { width: 64, height: 48, self_shadow: true, ..Default::default() }
}

/// One renderer's life: new, one frame, `into_context`.
fn cycle(ctx: Context) -> Context {
    let mut r = Renderer::new(ctx, scene(), options()).unwrap();
    let out = r.render().unwrap();
    assert!(out.stats.self_shadow, "self-shadowing ran (every part was made)");
    drop(out);
    r.into_context()
}

/// Fails each allocation of a construction in turn (n = 1, 2, ... until one succeeds) and
/// checks that every failure hands back a context holding no allocation, whatever step it
/// failed at. Returns the failures.
fn fail_each_allocation(mut ctx: Context) -> (Context, Vec<String>) {
    let mut failures = Vec::new();
    for n in 1.. {
        set_thread_faults(Some(&[Fault { point: FaultPoint::Alloc, nth: n, result: vk::Result::ERROR_OUT_OF_DEVICE_MEMORY }]));
        let made = Renderer::try_new(ctx, scene(), options());
        set_thread_faults(None);
        match made {
            Ok(r) => return (r.into_context(), failures),
            Err(e) => {
                let NewError { error, context } = *e;
                ctx = context;
                let what = error.to_string();
                assert!(matches!(error, umbrage::Error::Allocation { .. }), "allocation {n}: {what}");
                drop(error);
                assert_eq!(gpu_allocations(&ctx), (0, 0), "allocations left after failing at allocation {n} ({what})");
                failures.push(what);
            }
        }
        assert!(n < 1000, "the walk ends");
    }
    unreachable!()
}

/// A successful construction, a frame and `into_context`, then a construction failed at each
/// of its allocations in turn: every time, gpu-allocator holds no allocation afterwards; and
/// a renderer's life leaves no heap bytes behind.
///
/// The old hand-written teardown fails this: `into_context` dropped a list of fields that
/// missed some (`source_lights`, `geo`, `targets`, `pipes`, ...), leaking their heap memory on
/// every renderer (1056 bytes each with this scene).
#[test]
fn a_renderer_gives_back_everything_it_took() {
    let Some(mut ctx) = common::context() else {
        return;
    };
    assert_eq!(gpu_allocations(&ctx), (0, 0), "a fresh context holds no allocations");
    // Warm up (lazily built statics, the allocator's and the context's own bookkeeping),
    // then measure each further renderer's life. That bookkeeping still grows now and then
    // (once, at a point that varies from run to run); a leak shows in every life.
    for _ in 0..2 {
        ctx = cycle(ctx);
        assert_eq!(gpu_allocations(&ctx), (0, 0), "allocations left after into_context");
    }
    let mut grown = Vec::new();
    for _ in 0..5 {
        let held = heap_held();
        ctx = cycle(ctx);
        assert_eq!(gpu_allocations(&ctx), (0, 0), "allocations left after into_context");
        grown.push(heap_held() - held);
    }
    eprintln!("heap bytes each renderer left behind: {grown:?}");
    assert!(grown.iter().filter(|&&g| g == 0).count() >= 3, "renderers leak heap bytes: {grown:?}");

    // The failures.
    let failures;
    (ctx, failures) = fail_each_allocation(ctx);
    eprintln!("{} allocation points failed cleanly:\n  {}", failures.len(), failures.join("\n  "));
    assert!(failures.len() >= 5, "the walk reaches the later steps ({} failures)", failures.len());
    assert_eq!(gpu_allocations(&ctx), (0, 0));
    drop(ctx);
}
