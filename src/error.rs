//! One error type for the whole crate (gpu-allocator style): every failure a user can cause
//! is a variant with a message that names the file, the mesh or the missing feature.

#![warn(missing_docs)]

/// Everything that can go wrong in umbrage.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Bad user input: a file (scene TOML, OBJ, dump directory, expectations) or a
    /// command-line value. `location` is `path`, `path:line` where a line is known, or the
    /// flag.
    #[error("{location}: {msg}")]
    Input {
        /// `path` or `path:line` of the offending input.
        location: String,
        /// What is wrong with it.
        msg: String,
    },
    /// A mesh that cannot be used as asked (NaN, empty, non-manifold in the manifold path...).
    #[error("mesh '{name}': {msg}")]
    Mesh {
        /// The mesh's name (as in the scene or OBJ file).
        name: String,
        /// Why it cannot be used.
        msg: String,
    },
    /// Unknown built-in scene, method, shape or view name.
    #[error("unknown {what} '{name}' (expected one of: {expected})")]
    UnknownName {
        /// The kind of name, e.g. `"scene"` or `"method"`.
        what: &'static str,
        /// The name that was given.
        name: String,
        /// The accepted names, comma-separated.
        expected: String,
    },
    /// No Vulkan loader, driver or usable device.
    #[error(
        "no usable Vulkan device: {0}\n  hint: on Debian/Ubuntu install the CPU driver with \
             `apt-get install libvulkan1 mesa-vulkan-drivers vulkan-validationlayers` (lavapipe), \
             or run `make deps`"
    )]
    NoDevice(String),
    /// A Vulkan call failed: `call` names the entry point, `result` is what it returned.
    #[error("Vulkan error in {call}: {result:?}")]
    Vulkan {
        /// The Vulkan entry point, e.g. `vkCreateBuffer`.
        call: &'static str,
        /// What the call returned.
        #[source]
        result: ash::vk::Result,
    },
    /// gpu-allocator could not allocate memory for `name` (`size` bytes).
    #[error("allocating {name} ({size} bytes): {source}")]
    Allocation {
        /// What the memory was for.
        name: String,
        /// Requested size in bytes.
        size: u64,
        /// gpu-allocator's error.
        #[source]
        source: gpu_allocator::AllocationError,
    },
    /// An allocation would exceed the memory budget (set by the host, see
    /// [`crate::gpu::fault`]) or a scene's buffers would not fit the device's memory.
    #[error("out of GPU memory for {name}: {size} bytes requested, {used} bytes in use, limit {budget} bytes")]
    OutOfMemory {
        /// What the memory was for.
        name: String,
        /// Requested size in bytes.
        size: u64,
        /// Bytes already allocated.
        used: u64,
        /// The budget or heap size in bytes.
        budget: u64,
    },
    /// A device feature a requested path needs is missing.
    #[error("unsupported on this device: {0}")]
    Unsupported(String),
    /// Validation layers reported errors (only when validation is on).
    #[error("Vulkan validation reported {count} error(s); first: {first}")]
    Validation {
        /// Number of ERROR-severity messages since the log was last drained.
        count: usize,
        /// The first of them, verbatim.
        first: String,
    },
    /// An invariant of umbrage's own code did not hold (a bug in umbrage: please report it
    /// with the message).
    #[error("internal error (a bug in umbrage): {0}")]
    Internal(String),
    /// A [`ShadowPassDesc`](crate::pass::ShadowPassDesc) (or another creation option) that
    /// cannot be honoured as given, independent of the device: `field` names the option.
    #[error("{field}: {msg}")]
    InvalidDesc {
        /// The option, e.g. `"ShadowPassDesc::samples"`.
        field: &'static str,
        /// What is wrong with its value.
        msg: String,
    },
    /// The embedding API was called in a way its contract forbids (a wrong index, a frame of
    /// another pass or slot, an argument out of range). Nothing was recorded or changed.
    #[error("{0}")]
    Misuse(#[from] Misuse),
    /// Reading or writing a file failed.
    #[error("I/O error on {path}: {source}")]
    Io {
        /// The file or directory.
        path: String,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// How a caller broke the embedding API's contract ([`Error::Misuse`]). Each is detected
/// before anything is recorded, so the command buffer is unchanged.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Misuse {
    /// A light index past the frame's lights.
    #[error("light {index} out of range: the frame was prepared with {lights} light(s)")]
    LightIndex {
        /// The index given.
        index: usize,
        /// How many lights the frame has.
        lights: usize,
    },
    /// A ring slot past `frames_in_flight`.
    #[error("ring slot {slot} out of range (frames_in_flight = {slots})")]
    SlotOutOfRange {
        /// The slot given.
        slot: usize,
        /// How many slots the pass has.
        slots: usize,
    },
    /// A frame prepared by another `ShadowPass`.
    #[error("the frame was prepared by another ShadowPass")]
    ForeignFrame,
    /// A frame whose ring slot was prepared again since: its buffers now hold a newer frame.
    #[error("stale frame: ring slot {slot} was prepared again (frame {serial}, slot now holds frame {current})")]
    StaleFrame {
        /// The frame's slot.
        slot: usize,
        /// The frame's serial.
        serial: u64,
        /// The serial of the frame the slot holds now.
        current: u64,
    },
    /// A caster or sphere id that is not (or no longer) in the pass.
    #[error("unknown or removed {what} {id}")]
    UnknownId {
        /// `"caster"` or `"sphere caster"`.
        what: &'static str,
        /// The id as printed.
        id: String,
    },
    /// A caster, transparent-caster or sphere id made by another `ShadowPass`: ids carry
    /// the pass that made them, so one pass never moves, reshapes or removes another's caster.
    #[error("{what} {id} belongs to ShadowPass #{owner}, not to this one (#{this})")]
    ForeignId {
        /// `"caster"` or `"sphere caster"`.
        what: &'static str,
        /// The id as printed.
        id: String,
        /// The id of the pass that made it.
        owner: u64,
        /// The id of the pass it was given to.
        this: u64,
    },
    /// A call that needs an option the pass was not created with, or the other target model.
    #[error("{call} needs {needs}")]
    NotConfigured {
        /// The call, e.g. `"cmd_count_float"`.
        call: &'static str,
        /// What it needs, e.g. `"the dynamic-rendering target model"`.
        needs: &'static str,
    },
    /// A call made out of order (e.g. the uploads of a frame not yet recorded when the host's
    /// render pass has begun).
    #[error("{0}")]
    Order(String),
    /// An argument outside its documented range (a non-finite view, an empty target, a light
    /// with a zero direction, a declared layout the pass cannot take).
    #[error("{what}: {msg}")]
    Argument {
        /// The argument, e.g. `"ShadowView"`.
        what: &'static str,
        /// What is wrong with it.
        msg: String,
    },
}

/// `std::result::Result` with umbrage's [`Error`] as the default error type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An [`Error::Input`]: `location` is `path` or `path:line`.
    pub fn input(location: impl Into<String>, msg: impl Into<String>) -> Self {
        Error::Input { location: location.into(), msg: msg.into() }
    }
    /// An [`Error::Mesh`] for the mesh called `name`.
    pub fn mesh(name: impl Into<String>, msg: impl Into<String>) -> Self {
        Error::Mesh { name: name.into(), msg: msg.into() }
    }
    /// Maps a failed Vulkan call to [`Error::Vulkan`]: `.map_err(Error::vk("vkCreateBuffer"))`.
    pub fn vk(call: &'static str) -> impl Fn(ash::vk::Result) -> Error {
        move |result| Error::Vulkan { call, result }
    }
    /// An [`Error::Misuse`] for an argument out of range.
    pub fn argument(what: &'static str, msg: impl Into<String>) -> Self {
        Error::Misuse(Misuse::Argument { what, msg: msg.into() })
    }
    /// An [`Error::InvalidDesc`] for the creation option `field`.
    pub fn desc(field: &'static str, msg: impl Into<String>) -> Self {
        Error::InvalidDesc { field, msg: msg.into() }
    }
    /// An [`Error::Io`] on `path`.
    pub fn io(path: impl Into<String>, source: std::io::Error) -> Self {
        Error::Io { path: path.into(), source }
    }
}
