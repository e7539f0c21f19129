//! RAII for the renderer's GPU objects, which are destroyed with the [`Context`] that made
//! them rather than by a handle of their own.
//!
//! Why guards rather than self-destroying objects: the render layer's objects (geometry,
//! targets, pipelines, frame slots) take `&Context` to be destroyed, and the renderer owns
//! that context. Giving each its own device and allocator handles (as [`umbrage::pass`] does
//! with its `PassDevice`) would change every one of them; instead two small owners carry the
//! context beside them:
//!
//! - [`Guard`] borrows the context while a constructor builds its parts one by one: a part
//!   made by a step is guarded, a failure at a later step drops the guards made so far (in
//!   reverse order), and the finished parts are taken out with [`Guard::into_inner`].
//! - [`Owned`] owns the context and the object made with it: its `Drop` and
//!   [`Owned::into_context`] share one teardown (wait for the device, [`Destroy::destroy`],
//!   then drop the object as a whole, then the context), so no field list exists anywhere:
//!   a field added to the object later is dropped with it.
//!
//! Both wait for the device to be idle before destroying, so neither needs an `unsafe`
//! constructor: whatever was submitted with the object has finished by then.

use std::mem::ManuallyDrop;
use umbrage::gpu::Context;

/// Something made with a [`Context`] that must be destroyed with it. `destroy` releases the
/// Vulkan objects and memory; what stays (plain Rust data) is released by dropping the value.
pub(crate) trait Destroy {
    /// Destroys the Vulkan objects and frees the memory of `self` (once).
    ///
    /// # Safety
    ///
    /// The GPU no longer uses them (the device is idle, or nothing was submitted with them),
    /// and `ctx` is the context they were made with.
    unsafe fn destroy(&mut self, ctx: &Context);
}

impl<T: Destroy> Destroy for Option<T> {
    unsafe fn destroy(&mut self, ctx: &Context) {
        if let Some(v) = self {
            // SAFETY: forwarded to the caller's contract.
            unsafe { v.destroy(ctx) }
        }
    }
}

impl<T: Destroy> Destroy for Vec<T> {
    unsafe fn destroy(&mut self, ctx: &Context) {
        for v in self {
            // SAFETY: forwarded to the caller's contract.
            unsafe { v.destroy(ctx) }
        }
    }
}

/// Waits for the device to finish everything submitted, so anything may be destroyed.
fn wait_idle(ctx: &Context) {
    // SAFETY: the context's device is valid; an error (a lost device) still lets objects be
    // destroyed, as the GPU runs nothing more then.
    let _ = unsafe { ctx.device.device_wait_idle() };
}

/// A value under construction, destroyed with the borrowed context unless taken out with
/// [`Guard::into_inner`] (see the module docs).
pub(crate) struct Guard<'a, T: Destroy> {
    ctx: &'a Context,
    value: Option<T>,
}

impl<'a, T: Destroy> Guard<'a, T> {
    /// Guards `value`, made with `ctx`.
    pub(crate) fn new(ctx: &'a Context, value: T) -> Self {
        Guard { ctx, value: Some(value) }
    }
    /// The value, no longer guarded.
    pub(crate) fn into_inner(mut self) -> T {
        self.value.take().expect("a guard holds its value until into_inner")
    }
}

impl<T: Destroy> std::ops::Deref for Guard<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        self.value.as_ref().expect("a guard holds its value until into_inner")
    }
}

impl<T: Destroy> std::ops::DerefMut for Guard<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        self.value.as_mut().expect("a guard holds its value until into_inner")
    }
}

impl<T: Destroy> Drop for Guard<'_, T> {
    fn drop(&mut self) {
        if let Some(mut v) = self.value.take() {
            wait_idle(self.ctx);
            // SAFETY: the device is idle and `v` was made with `self.ctx` (`Guard::new`).
            unsafe { v.destroy(self.ctx) };
        }
    }
}

/// Parts and the context that made them, owned together: dropping it, or
/// [`Owned::into_context`], destroys the parts' objects, drops the parts whole, then drops or
/// hands back the context (see the module docs).
pub(crate) struct Owned<T: Destroy> {
    /// The parts (their fields are used directly, disjointly from `ctx`). Declared before
    /// `ctx`: after `Drop::drop` destroyed their objects, they are dropped first.
    pub(crate) parts: T,
    /// The context `parts` were made with, dropped last.
    pub(crate) ctx: Context,
}

impl<T: Destroy> Owned<T> {
    /// Owns `parts`, made with `ctx` (guarded parts are taken out of their guards first).
    pub(crate) fn new(parts: T, ctx: Context) -> Self {
        Owned { parts, ctx }
    }

    /// Destroys and drops the parts and hands the context back.
    pub(crate) fn into_context(self) -> Context {
        let mut me = ManuallyDrop::new(self);
        me.destroy_parts();
        // SAFETY: `me` is never dropped (`ManuallyDrop`) or used again, so each field is
        // released once: `parts` dropped in place (as `Drop` would, in declaration order),
        // then `ctx` moved out.
        unsafe {
            std::ptr::drop_in_place(&mut me.parts);
            std::ptr::read(&me.ctx)
        }
    }

    /// The teardown both `Drop` and `into_context` run, once: waits for the device and
    /// destroys the parts' objects while the context is alive.
    fn destroy_parts(&mut self) {
        wait_idle(&self.ctx);
        // SAFETY: the device is idle and `parts` were made with `ctx` (`Owned::new`); they are
        // destroyed once, as the callers only drop them afterwards.
        unsafe { self.parts.destroy(&self.ctx) }
    }
}

impl<T: Destroy> Drop for Owned<T> {
    fn drop(&mut self) {
        self.destroy_parts();
        // Then the fields drop in declaration order: the parts, then the context.
    }
}

/// The render layer's objects, each destroyed with its own `destroy`.
mod impls {
    use super::{Context, Destroy};
    use crate::{
        pipelines::FramePipelines, scene_gpu::SceneGeometry, sphere_gpu::SphereGeometry, stages::selfshadow::SelfShadow,
        stages::shadowmap::ShadowMapper, targets::Targets,
    };

    macro_rules! safe_destroy {
        ($($t:ty),*) => {$(
            impl Destroy for $t {
                unsafe fn destroy(&mut self, ctx: &Context) {
                    <$t>::destroy(self, ctx)
                }
            }
        )*};
    }
    safe_destroy!(SceneGeometry, SphereGeometry, Targets, SelfShadow, ShadowMapper);

    impl Destroy for FramePipelines {
        unsafe fn destroy(&mut self, ctx: &Context) {
            // SAFETY: the same contract (no pending command buffer uses them).
            unsafe { FramePipelines::destroy(self, ctx) }
        }
    }
}
