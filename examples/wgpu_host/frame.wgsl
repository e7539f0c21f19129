// The wgpu host's frame in WGSL: the ambient / G-buffer pass, the per-light illumination
// (drawn where the stencil count is 0) and the tone map. A port of umbrage's own frame
// (shaders/gbuffer.*, illuminate.frag, tonemap.frag): Blinn-Phong with umbrage's range
// attenuation and spot falloff, added over the ambient term in a float target.

// ---- 1. Ambient + G-buffer: every mesh, two-sided, depth LESS -------------------------------

struct Mesh {
    // Object -> clip, composed in f64 exactly as the shadow pass composes its volumes' MVP
    // (then y negated for wgpu's y-up clip space).
    mvp: mat4x4<f32>,
    // Object -> eye-relative world (f64 composed, f32 stored).
    model_rel: mat4x4<f32>,
    // Columns of the normals' linear map (inverse transpose of the model's 3x3).
    n0: vec4<f32>,
    n1: vec4<f32>,
    n2: vec4<f32>,
    color: vec4<f32>,
    ambient: vec4<f32>,
}

@group(0) @binding(5) var<uniform> mesh: Mesh;

struct GVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) pos: vec3<f32>,
    @location(1) @interpolate(flat) normal: vec3<f32>,
}

@vertex
fn gbuffer_vs(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> GVertex {
    var out: GVertex;
    out.clip = mesh.mvp * vec4<f32>(p, 1.0);
    out.pos = (mesh.model_rel * vec4<f32>(p, 1.0)).xyz;
    out.normal = mat3x3<f32>(mesh.n0.xyz, mesh.n1.xyz, mesh.n2.xyz) * n;
    return out;
}

struct GOut {
    @location(0) accum: vec4<f32>,
    @location(1) albedo: vec4<f32>,
    @location(2) normal: vec4<f32>,
    @location(3) position: vec4<f32>,
}

@fragment
fn gbuffer_fs(v: GVertex, @builtin(front_facing) front: bool) -> GOut {
    var out: GOut;
    var n = normalize(v.normal);
    // Two-sided: shade the visible side (as umbrage's renderer does for open meshes).
    if !front {
        n = -n;
    }
    out.accum = vec4<f32>(mesh.color.rgb * mesh.ambient.rgb, 1.0);
    out.albedo = vec4<f32>(mesh.color.rgb, 1.0);
    out.normal = vec4<f32>(n, 0.0);
    // w = 1 marks a surface (background stays 0 from the clear).
    out.position = vec4<f32>(v.pos, 1.0);
    return out;
}

// ---- 2. Per light: full-screen triangle over the light's scissor, stencil EQUAL 0 -------------

struct LightBlock {
    // xyz relative to the eye, w = 1; or xyz towards the light, w = 0 (directional).
    position: vec4<f32>,
    // rgb = colour * intensity.
    color: vec4<f32>,
    // xyz = travel direction, w = cos(half cone) (-2 when not a spot).
    spot: vec4<f32>,
    // x = radius (0: unbounded).
    params: vec4<f32>,
}

@group(0) @binding(0) var t_albedo: texture_2d<f32>;
@group(0) @binding(1) var t_normal: texture_2d<f32>;
@group(0) @binding(2) var t_position: texture_2d<f32>;
@group(0) @binding(3) var<uniform> light: LightBlock;

@vertex
fn fullscreen_vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn illuminate_fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<i32>(frag.xy);
    let pos = textureLoad(t_position, px, 0);
    if pos.w == 0.0 {
        discard;
    }
    let n = normalize(textureLoad(t_normal, px, 0).xyz);
    let albedo = textureLoad(t_albedo, px, 0).rgb;
    let to_light = light.position.xyz - pos.xyz * light.position.w;
    let dist = length(to_light);
    let l = to_light / max(dist, 1e-30);
    let ndotl = dot(n, l);
    if ndotl <= 0.0 {
        discard;
    }
    var atten = 1.0;
    if light.params.x > 0.0 {
        let r = clamp(dist / light.params.x, 0.0, 1.0);
        atten = (1.0 - r * r) * (1.0 - r * r);
    }
    if light.spot.w > -1.5 {
        let c = dot(-l, normalize(light.spot.xyz));
        atten = atten * smoothstep(light.spot.w, mix(light.spot.w, 1.0, 0.15), c);
    }
    let v = normalize(-pos.xyz);
    let h = normalize(l + v);
    let spec = pow(max(dot(n, h), 0.0), 48.0) * 0.3;
    return vec4<f32>((albedo * ndotl + vec3<f32>(spec)) * light.color.rgb * atten, 0.0);
}

// ---- 3. Tone map into the sRGB output ----------------------------------------------------------

@group(0) @binding(4) var t_accum: texture_2d<f32>;

@fragment
fn tonemap_fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(t_accum, vec2<i32>(frag.xy), 0).rgb;
    return vec4<f32>(vec3<f32>(1.0) - exp(-c * 1.1), 1.0);
}
