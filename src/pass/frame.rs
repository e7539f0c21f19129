//! One frame's CPU work: per light the plan (culling, cases, possible silhouettes, index
//! lists), packed into the ring slot's stream, and the statistics `--stats` reports.

use super::casters::{CasterTable, Upload};
use super::compute::frame::ComputeFrame;
use super::desc::{Counter, DepthDirection, IndexFormat, PassSettings, Technique};
use super::stats::{CasterStats, CpuMs, LightStats, PartStats, Totals, Triangles};
use crate::error::{Error, Result};
use crate::geom::{Camera, Light, LightKind};
use crate::shadow::{self, Case, CasterKind, LightPlan, PlanInput, PlanOptions};
use ash::vk;
use glam::{DMat4, DVec3, Mat4, Vec3, Vec4};
use std::cell::Cell;

/// The host's camera for one frame, as the pass needs it to land its volumes exactly on the
/// host's depth values: the eye in f64 and the host's eye-relative view and projection (the
/// host draws its scene with `proj * view * (world - eye)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowView {
    /// The eye in world space (f64: scenes far from the origin keep their precision).
    pub eye: DVec3,
    /// World directions -> view space: the view matrix without its translation.
    pub view: Mat4,
    /// View -> Vulkan clip space (infinite far plane for [`DepthMode::Infinite`](super::DepthMode),
    /// finite for `Clamp`).
    pub proj: Mat4,
    /// The target's size in pixels (scissor rectangles are computed for it).
    pub width: u32,
    /// The target's height in pixels.
    pub height: u32,
}

impl ShadowView {
    /// The view of a host camera given as its usual (world -> view) matrix `view`, with its
    /// translation: the pass needs the eye in f64 and the rotation alone, so it strips the
    /// translation here (`eye` is the camera's world position, `view` maps it to the origin).
    /// `proj` is the host's view -> Vulkan clip projection (forward or reverse-Z, as the pass
    /// was created for), `size` the target's `(width, height)`.
    ///
    /// Errors: [`Error::Misuse`] when `view` does not map `eye` to the origin (to within
    /// 1e-4 of the scene's scale), or is not a rigid rotation plus translation.
    ///
    /// ```
    /// use glam::{DVec3, Mat4, Vec3};
    /// use umbrage::pass::ShadowView;
    /// let eye = Vec3::new(0.0, 2.0, 6.0);
    /// let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
    /// let proj = glam::camera::rh::proj::vulkan::perspective_infinite(1.0, 1.0, 0.1);
    /// let v = ShadowView::from_view_matrix(eye.as_dvec3(), view, proj, (640, 480))?;
    /// assert_eq!(v.view.w_axis.truncate(), Vec3::ZERO);
    /// assert!((v.world_view_proj() - proj * view).abs_diff_eq(Mat4::ZERO, 1e-5));
    /// # Ok::<(), umbrage::Error>(())
    /// ```
    pub fn from_view_matrix(eye: DVec3, view: Mat4, proj: Mat4, size: (u32, u32)) -> Result<ShadowView> {
        let v = view.as_dmat4();
        let at_eye = v.transform_point3(eye);
        let scale = eye.length().max(1.0);
        if !at_eye.is_finite() || at_eye.length() > 1e-4 * scale {
            return Err(Error::argument(
                "ShadowView::from_view_matrix",
                format!("the view matrix maps the eye {eye} to {at_eye}, not to the origin: pass the camera's own view matrix"),
            ));
        }
        let r = glam::DMat3::from_mat4(v);
        if !(r * r.transpose()).abs_diff_eq(glam::DMat3::IDENTITY, 1e-4) || (v.row(3) - glam::DVec4::W).length() > 1e-9 {
            return Err(Error::argument("ShadowView::from_view_matrix", "the view matrix is not a rotation and a translation"));
        }
        let rotation = Mat4::from_mat3(glam::Mat3::from_mat4(view));
        let out = ShadowView { eye, view: rotation, proj, width: size.0, height: size.1 };
        out.check()?;
        Ok(out)
    }

    /// The same view with a forward projection: the planner's near plane, frustum, scissors
    /// and depth bounds are computed on it.
    pub(crate) fn forward(&self, direction: DepthDirection) -> ShadowView {
        match direction {
            DepthDirection::Forward => *self,
            DepthDirection::Reverse => ShadowView { proj: super::desc::reverse_z(self.proj), ..*self },
        }
    }

    /// World -> clip, composed in f64 (the planner's frustum and scissor tests).
    pub fn world_view_proj(&self) -> Mat4 {
        (self.proj.as_dmat4() * self.view.as_dmat4() * DMat4::from_translation(-self.eye)).as_mat4()
    }
    pub(crate) fn check(&self) -> Result<()> {
        if !(self.eye.is_finite() && self.view.is_finite() && self.proj.is_finite()) {
            return Err(Error::argument("ShadowView", "eye, view or projection is not finite"));
        }
        if self.width == 0 || self.height == 0 {
            return Err(Error::argument("ShadowView", format!("empty target {}x{}", self.width, self.height)));
        }
        Ok(())
    }
}

/// One index-stream draw of a caster chunk.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Draw {
    /// The chunk's dual-length vertex buffer.
    pub vertices: vk::Buffer,
    /// Byte offset of the indices (or naive vertices) in the frame's stream.
    pub offset: u64,
    pub count: u32,
    pub format: IndexFormat,
    /// The case of the caster part this chunk belongs to (its pipeline and sign follow it).
    pub case: Case,
    /// A light cap (drawn with the depth-NEVER pipeline by the stencil counter).
    pub light_cap: bool,
    /// GPU silhouettes: `offset` is the byte offset of the draw's
    /// `VkDrawIndexedIndirectCommand` in the frame's compute records, the indices (u16) are in
    /// its compute output buffer, and `count` is unknown (0) until read back.
    pub indirect: bool,
}

/// Edge-quad geometry of a caster (static buffers).
#[derive(Clone, Copy, Debug)]
pub(crate) struct EdgeQuadDraw {
    pub vertices: vk::Buffer,
    pub indices: vk::Buffer,
    pub face_indices: u32,
    pub quad_indices: u32,
}

/// One caster's volume for one light.
#[derive(Clone, Debug)]
pub(crate) struct CasterDraw {
    pub case: Case,
    pub mvp: Mat4,
    pub light_object: Vec4,
    /// `Some(t)` for a transparent caster (light-intensity map, not the opaque counter).
    pub transmittance: Option<Vec3>,
    pub draws: Vec<Draw>,
    pub edge_quad: Option<EdgeQuadDraw>,
}

/// One light of a prepared frame.
#[derive(Clone, Debug)]
pub struct LightFrame {
    /// The light's scissor rectangle (the whole target when unbounded): the determination
    /// clears and draws only inside it, and the host's lighting pass should use it too.
    pub scissor: vk::Rect2D,
    /// The light's depth range when the pass uses depth bounds; `(0, 1)` passes everything.
    pub depth_bounds: Option<(f32, f32)>,
    /// What `--stats` reports for this light.
    pub stats: LightStats,
    /// The plan as the planner made it (cases, silhouettes, counts per caster).
    pub plan: LightPlan,
    /// The value the determination clears the counter to inside the scissor: 0, or with
    /// [`Method::ZPassClear`](crate::shadow::Method) the number of volumes containing the eye.
    pub counter_clear: u32,
    pub(crate) casters: Vec<CasterDraw>,
}

impl LightFrame {
    /// Whether any opaque volume is drawn for this light (else the stencil stays 0 inside
    /// the scissor and every pixel there is lit).
    pub fn has_opaque_volumes(&self) -> bool {
        self.casters.iter().any(|c| c.case != Case::Culled && c.transmittance.is_none())
    }
    /// Whether any transparent caster's volume is drawn (the light-intensity map is needed).
    pub fn has_transparent_volumes(&self) -> bool {
        self.casters.iter().any(|c| c.case != Case::Culled && c.transmittance.is_some())
    }
}

/// The CPU work of one frame ([`ShadowPass::prepare`](super::ShadowPass::prepare)): what the
/// recording calls draw. It refers to buffers of ring slot [`slot`](Self::slot), valid until
/// that slot is prepared again.
#[derive(Debug)]
pub struct PreparedFrame {
    /// The id of the pass that prepared it.
    pub(crate) pass: u64,
    pub(crate) slot: usize,
    pub(crate) serial: u64,
    pub(crate) stream: vk::Buffer,
    pub(crate) uploads: Vec<Upload>,
    pub(crate) uploads_recorded: Cell<bool>,
    /// Per light, in the order given to `prepare`.
    pub lights: Vec<LightFrame>,
    /// Totals over all lights (triangles, bytes, cases).
    pub totals: Totals,
    /// CPU time of this frame's planning (the recording adds `record` on the host's side).
    pub cpu_ms: CpuMs,
    /// The settings the frame was prepared with.
    pub settings: PassSettings,
    /// Things the host should tell its user (e.g. a possible 8-bit stencil overflow).
    pub warnings: Vec<String>,
    pub(crate) extent: vk::Extent2D,
    /// The GPU silhouettes of [`Technique::Compute`] (counts read back by
    /// [`ShadowPass::read_back_counts`](super::ShadowPass::read_back_counts)).
    pub(crate) compute: Option<ComputeFrame>,
}

impl PreparedFrame {
    /// The ring slot this frame uses.
    pub fn slot(&self) -> usize {
        self.slot
    }
    /// The target size the frame was prepared for.
    pub fn extent(&self) -> vk::Extent2D {
        self.extent
    }
    /// How many frames were prepared before this one.
    pub fn serial(&self) -> u64 {
        self.serial
    }
    /// Caster buffers this frame must copy before any volume is drawn (recorded by
    /// [`ShadowPass::cmd_upload`](super::ShadowPass::cmd_upload)).
    pub fn pending_uploads(&self) -> usize {
        if self.uploads_recorded.get() {
            0
        } else {
            self.uploads.len()
        }
    }
}

/// The plans, packed: what `prepare` builds before writing the slot's stream.
pub(crate) struct Packed {
    pub stream: Vec<u8>,
    /// The compute pass's layout ([`Technique::Compute`]).
    pub compute: Option<ComputeFrame>,
    pub lights: Vec<LightFrame>,
    pub totals: Totals,
    pub cpu: CpuMs,
}

/// Inputs of [`pack`].
pub(crate) struct PackInput<'a> {
    pub view: &'a ShadowView,
    /// The host's depth direction (the planner works on the forward view).
    pub direction: DepthDirection,
    pub lights: &'a [Light],
    pub settings: PassSettings,
    pub u8_ok: bool,
    pub depth_bounds: bool,
    /// Plan the casters (false: every caster culled, scissors only).
    pub casters: bool,
    /// The receiver plane of [`Technique::Planar`](super::Technique::Planar) (world, `n·x + d = 0`).
    pub planar_receiver: glam::DVec4,
    /// The analytic sphere casters (planned after the mesh casters, per light).
    pub spheres: &'a [super::spheres::SphereCaster],
}

/// Plans every light and packs the index streams (or naive vertices) into one byte stream.
pub(crate) fn pack(table: &CasterTable, input: &PackInput) -> Packed {
    let view = input.view;
    // The volumes are drawn with the host's projection; the planner (near plane, frustum,
    // scissor, depth bounds) works on its forward equivalent.
    let fwd = view.forward(input.direction);
    let view_proj = fwd.world_view_proj();
    let vp_rel_d = view.proj.as_dmat4() * view.view.as_dmat4();
    let camera = Camera { eye: view.eye.as_vec3(), ..Camera::default() };
    let edge_quads = input.settings.technique == Technique::EdgeQuads;
    let gpu_silhouettes = input.settings.technique == Technique::Compute;
    let mut compute = gpu_silhouettes.then(ComputeFrame::default);
    let method = input.settings.technique.method();
    let mvps: Vec<Mat4> = table.live.iter().map(|g| (vp_rel_d * DMat4::from_translation(-view.eye) * g.transform).as_mat4()).collect();
    let full = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: vk::Extent2D { width: view.width, height: view.height } };

    let mut stream: Vec<u8> = Vec::new();
    let mut totals = Totals::default();
    let mut cpu = CpuMs::default();
    let mut lights = Vec::with_capacity(input.lights.len());
    for (li, light) in input.lights.iter().enumerate() {
        // Each part (connected component) of a caster gets its own case; every draw carries it.
        let plan = shadow::plan_light_with(
            &PlanInput { camera: &camera, width: view.width, height: view.height, view_proj, light, method },
            if input.casters { &table.cpu } else { &[] },
            &PlanOptions { edge_quads, case_per_part: true, gpu_silhouettes, no_culling: !input.settings.toggles.culling },
        );
        let mut plan = plan;
        let planar_mvp = (input.settings.technique == Technique::Planar).then(|| flatten(&mut plan, table, light, input.planar_receiver));
        cpu.silhouettes += plan.silhouette_ms;
        // plan_ms covers the whole planner, facing and silhouettes included
        cpu.plan += (plan.plan_ms - plan.silhouette_ms).max(0.0);
        let mut casters = Vec::with_capacity(plan.casters.len());
        let mut cstats = Vec::with_capacity(plan.casters.len());
        for cp in &plan.casters {
            let caster = &table.cpu[cp.caster];
            let gpu = &table.live[cp.caster];
            let mut draws = Vec::new();
            let mut index_bytes = 0u64;
            let mut vertex_bytes = 0u64;
            let mut fmt_used = "none";
            for cd in &cp.chunks {
                let chunk = &caster.chunks[cd.chunk];
                let n = chunk.vertices.len();
                for (indices, cap) in [(&cd.volume, false), (&cd.light_cap, true)] {
                    if indices.is_empty() {
                        continue;
                    }
                    let fmt = match input.settings.index_format {
                        IndexFormat::Auto | IndexFormat::U8 if input.u8_ok && 2 * n <= 256 => IndexFormat::U8,
                        IndexFormat::Auto | IndexFormat::U8 => IndexFormat::U16,
                        f => f,
                    };
                    fmt_used = fmt.name();
                    align(&mut stream, 16);
                    let offset = stream.len() as u64;
                    match fmt {
                        IndexFormat::U8 => stream.extend(indices.iter().map(|&i| i as u8)),
                        IndexFormat::U16 => stream.extend(indices.iter().flat_map(|&i| i.to_le_bytes())),
                        IndexFormat::U32 => stream.extend(indices.iter().flat_map(|&i| (i as u32).to_le_bytes())),
                        IndexFormat::Naive | IndexFormat::Auto => {
                            for &i in indices.iter() {
                                let i = i as usize;
                                let (v, wv) = if i < n { (chunk.vertices[i], 1.0f32) } else { (chunk.vertices[i - n], 0.0) };
                                for f in [v.x, v.y, v.z, wv] {
                                    stream.extend(f.to_le_bytes());
                                }
                            }
                        }
                    }
                    let bytes = stream.len() as u64 - offset;
                    if fmt == IndexFormat::Naive {
                        vertex_bytes += bytes;
                    } else {
                        index_bytes += bytes;
                    }
                    draws.push(Draw {
                        vertices: gpu.chunks[cd.chunk].raw,
                        offset,
                        count: indices.len() as u32,
                        format: fmt,
                        case: cd.case,
                        light_cap: cap,
                        indirect: false,
                    });
                }
            }
            if let (Some(cf), Some(st)) = (compute.as_mut(), gpu.compute.as_ref()) {
                if cp.parts.iter().any(|p| p.path == "compute" && p.case != Case::Culled) {
                    let buffers: Vec<vk::Buffer> = gpu.chunks.iter().map(|b| b.raw).collect();
                    cf.add_caster(li, cstats.len(), cp.caster, caster, st, cp, &buffers, &mut draws);
                    fmt_used = IndexFormat::U16.name();
                }
            }
            let tris = Triangles { sides: cp.sides as u64, dark_cap: cp.dark_cap as u64, light_cap: cp.light_cap as u64 };
            let ntris = tris.total();
            totals.triangles.add(&tris);
            totals.index_bytes += index_bytes;
            totals.vertex_bytes += vertex_bytes;
            totals.draws += draws.len() as u64 + if cp.path == "edgequad" { 2 } else { 0 };
            match cp.case {
                Case::Culled => totals.cases.culled += 1,
                Case::ZPass => totals.cases.zpass += 1,
                Case::ZFail => totals.cases.zfail += 1,
                Case::ZFailLightCap => totals.cases.zfail_light_cap += 1,
            }
            cstats.push(CasterStats {
                name: caster.name.clone(),
                case: case_name(cp.case).to_string(),
                silhouette_edges: cp.silhouette_edges as u64,
                triangles: tris,
                index_bytes,
                vertex_bytes,
                bytes_per_triangle: if ntris > 0 { (index_bytes + vertex_bytes) as f64 / ntris as f64 } else { 0.0 },
                index_format: fmt_used.to_string(),
                dark_cap_kind: format!("{:?}", cp.dark_cap_kind),
                path: cp.path.to_string(),
                path_reason: match &caster.kind {
                    CasterKind::Multiplicity { reason } => reason.clone(),
                    _ => String::new(),
                },
                multiplicity_max: cp.multiplicity_max,
                parts: cp
                    .parts
                    .iter()
                    .map(|p| PartStats {
                        part: p.part,
                        case: case_name(p.case).to_string(),
                        path: p.path.to_string(),
                        silhouette_edges: p.silhouette_edges as u64,
                        triangles: Triangles { sides: p.sides as u64, dark_cap: p.dark_cap as u64, light_cap: p.light_cap as u64 },
                    })
                    .collect(),
                sphere: None,
            });
            let edge_quad = match (&gpu.edge_quads, cp.path == "edgequad") {
                (Some(eq), true) => Some(EdgeQuadDraw {
                    vertices: eq.vertices.raw,
                    indices: eq.indices.raw,
                    face_indices: eq.face_indices,
                    quad_indices: eq.quad_indices,
                }),
                _ => None,
            };
            casters.push(CasterDraw {
                case: cp.case,
                mvp: match &planar_mvp {
                    // Flattened: the caster's triangles projected from the light onto the plane.
                    Some(m) => (vp_rel_d * DMat4::from_translation(-view.eye) * *m * table.live[cp.caster].transform).as_mat4(),
                    None => mvps[cp.caster],
                },
                light_object: Vec4::from_array(cp.light_object),
                transmittance: caster.transmittance,
                draws,
                edge_quad,
            });
        }
        if input.casters {
            let sin = super::spheres::SphereInput {
                view,
                scale: super::spheres::view_scale(&fwd),
                light,
                technique: input.settings.technique,
                planar_receiver: input.planar_receiver,
            };
            let start = std::time::Instant::now();
            super::spheres::pack_light(input.spheres, &sin, &mut stream, &mut totals, &mut casters, &mut cstats);
            // The spheres' planning (tangency circles, n, volumes) counts as planning.
            cpu.plan += start.elapsed().as_secs_f64() * 1e3;
        }
        let scissor = plan
            .scissor
            .map(|[x, y, sw, sh]| vk::Rect2D {
                offset: vk::Offset2D { x: x as i32, y: y as i32 },
                extent: vk::Extent2D { width: sw, height: sh },
            })
            .filter(|r| r.extent.width > 0 && r.extent.height > 0 && input.settings.toggles.scissor)
            .unwrap_or(full);
        let depth_bounds = if input.depth_bounds { plan.depth_bounds } else { None };
        let depth_bounds = match input.direction {
            DepthDirection::Forward => depth_bounds,
            DepthDirection::Reverse => depth_bounds.map(|(lo, hi)| reversed_bounds(lo, hi)),
        };
        let (eye_volumes, near_plane_split) = if method == shadow::Method::ZPassClear {
            let [c0, c1, c2, c3] = near_corners(&fwd);
            let counts = super::eye::volumes_containing(&[view.eye, c0, c1, c2, c3], light, &plan, table);
            (Some(counts[0]), Some(counts[1..].iter().any(|&c| c != counts[0])))
        } else {
            (None, None)
        };
        let stats = LightStats {
            index: li,
            kind: light_kind_name(light.kind).to_string(),
            scissor: plan.scissor.filter(|_| input.settings.toggles.scissor),
            depth_bounds: depth_bounds.map(|(a, b)| [a, b]),
            casters: cstats,
            eye_volumes,
            near_plane_split,
        };
        let counter_clear = eye_volumes.unwrap_or(0).max(0) as u32;
        lights.push(LightFrame { scissor, depth_bounds, stats, plan, counter_clear, casters });
    }
    align(&mut stream, 16);
    totals.bytes_sent = totals.index_bytes + totals.vertex_bytes;
    Packed { stream, lights, totals, cpu, compute }
}

/// Planar projected shadows: every drawn opaque caster's plan becomes all its triangles (w = 1
/// copies) in one z-pass list, and the matrix flattening world space onto the receiver plane
/// `p` from the light `L` is returned: `M = (p·L) I - L pᵀ`. Transparent casters, and every
/// caster when the light is not above the plane, are culled.
fn flatten(plan: &mut LightPlan, table: &CasterTable, light: &Light, p: glam::DVec4) -> DMat4 {
    let l = light.homogeneous().as_dvec4();
    let pl = p.dot(l);
    let m = DMat4::from_diagonal(glam::DVec4::splat(pl)) - DMat4::from_cols(l * p.x, l * p.y, l * p.z, l * p.w);
    for cp in &mut plan.casters {
        let caster = &table.cpu[cp.caster];
        if cp.case == Case::Culled || caster.transmittance.is_some() || !(pl > 0.0) {
            cp.case = Case::Culled;
            cp.chunks.clear();
            cp.parts.clear();
            cp.sides = 0;
            cp.dark_cap = 0;
            cp.light_cap = 0;
            continue;
        }
        cp.case = Case::ZPass;
        cp.path = "planar";
        cp.parts.clear();
        cp.silhouette_edges = 0;
        cp.dark_cap = 0;
        cp.light_cap = 0;
        cp.dark_cap_kind = shadow::DarkCap::None;
        cp.chunks = caster
            .chunks
            .iter()
            .enumerate()
            .map(|(ci, ch)| shadow::ChunkDraw {
                chunk: ci,
                case: Case::ZPass,
                volume: ch.local_tris.iter().flatten().copied().collect(),
                light_cap: Vec::new(),
            })
            .collect();
        cp.sides = caster.chunks.iter().map(|c| c.local_tris.len()).sum();
    }
    m
}

/// Forward depth bounds `[lo, hi]` as reverse-Z bounds `[1 - hi, 1 - lo]`, rounded outwards
/// to f32 (the subtraction is exact in f64).
fn reversed_bounds(lo: f32, hi: f32) -> (f32, f32) {
    let (a, b) = (1.0 - hi as f64, 1.0 - lo as f64);
    let (mut a32, mut b32) = (a as f32, b as f32);
    if a32 as f64 > a {
        a32 = f32::from_bits(a32.to_bits().saturating_sub(1));
    }
    if (b32 as f64) < b {
        b32 = f32::from_bits(b32.to_bits() + 1);
    }
    (a32.clamp(0.0, 1.0), b32.clamp(0.0, 1.0))
}

/// The near-plane rectangle's corners in world space (forward Vulkan depth 0).
fn near_corners(view: &ShadowView) -> [DVec3; 4] {
    let inv = (view.proj.as_dmat4() * view.view.as_dmat4()).inverse();
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, y)| {
        let h = inv * glam::DVec4::new(x, y, 0.0, 1.0);
        h.truncate() / h.w + view.eye
    })
}

/// 8-bit stencil counts wrap at 256: a pixel inside a multiple of 256 volumes reads as lit.
/// Flags lights whose drawn casters could nest that deep (a heuristic: one caster folding 256
/// times over itself is not detected).
pub(crate) fn overflow_warnings(table: &CasterTable, lights: &[LightFrame], counter: Counter) -> Vec<String> {
    let mut warnings = Vec::new();
    if counter != Counter::Stencil {
        return warnings;
    }
    for (li, l) in lights.iter().enumerate() {
        let drawn: usize = l.plan.casters.iter().filter(|c| c.case != Case::Culled).map(|c| table.live[c.caster].shells).sum();
        if drawn > 255 {
            warnings.push(format!(
                "light {li}: {drawn} closed shells cast shadow volumes; pixels inside 256k of them wrap to 0 in the 8-bit stencil and read as lit (Counter::Float counts exactly)"
            ));
        }
    }
    warnings
}

/// Rejects lights the planner cannot use (NaN or infinite values, a zero direction).
pub(crate) fn check_lights(lights: &[Light]) -> Result<()> {
    for (i, l) in lights.iter().enumerate() {
        let finite = l.position.is_finite() && l.direction.is_finite() && l.color.is_finite() && l.intensity.is_finite();
        let dir_ok = l.kind == LightKind::Point || l.direction.length_squared() > 0.0;
        if !finite || !dir_ok || l.radius.is_some_and(|r| !(r > 0.0)) {
            return Err(Error::argument("light", format!("light {i}: not finite, zero direction or non-positive radius ({l:?})")));
        }
        if l.area.is_some() {
            return Err(Error::argument(
                "light",
                format!(
                    "light {i} is an area light: the pass determines point, spot and directional lights; expand it into its \
                     point-light samples first (geom::area::expand_lights), one determination and lighting pass each"
                ),
            ));
        }
    }
    Ok(())
}

/// The `--stats` name of a case.
pub fn case_name(c: Case) -> &'static str {
    match c {
        Case::Culled => "culled",
        Case::ZPass => "zpass",
        Case::ZFail => "zfail",
        Case::ZFailLightCap => "zfail_light_cap",
    }
}

fn light_kind_name(k: LightKind) -> &'static str {
    match k {
        LightKind::Point => "point",
        LightKind::Spot => "spot",
        LightKind::Directional => "directional",
    }
}

fn align(v: &mut Vec<u8>, a: usize) {
    while !v.len().is_multiple_of(a) {
        v.push(0);
    }
}
