#version 450
// Analytic spheres, G-buffer pass: the ray from the eye (the origin: positions are
// eye-relative) through this fragment of the bounding cube meets the exact sphere; the hit's
// depth is written (so the shadow determination and illumination see the exact surface),
// with the exact normal and position in the G-buffer. Misses are discarded.
layout(location = 0) in vec3 v_pos;
layout(location = 1) flat in vec3 v_center;
layout(location = 2) flat in vec3 v_color;
layout(location = 3) flat in float v_radius;

// @variant MS MSAA
// The MS variant (multisampled targets) shades per sample (it reads gl_SampleID) and casts
// each sample's ray through its own location, gl_FragCoord under sample shading, unprojected
// with the block's ray terms (SpherePush): every sample gets the exact depth, normal and
// position of its own ray's hit.
layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 ambient;
#ifdef MSAA
    vec4 ray_x;
    vec4 ray_y;
    vec4 ray_0;
#endif
} pc;

layout(location = 0) out vec4 out_accum;
layout(location = 1) out vec4 out_albedo;
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_position;

// The smooth shading normal in one float (normal.w): octahedral, 12 bits a component, an
// integer below 2^24 (exact in f32; illuminate.frag unpacks it).
float pack_normal(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 e = n.xy;
    if (n.z < 0.0) {
        e = (vec2(1.0) - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    }
    vec2 q = floor(clamp(e * 0.5 + 0.5, 0.0, 1.0) * 4095.0 + 0.5);
    return q.x * 4096.0 + q.y;
}

void main() {
#ifdef MSAA
    vec4 near = pc.ray_x * gl_FragCoord.x + pc.ray_y * gl_FragCoord.y + pc.ray_0;
    // gl_SampleID in the interface makes the pass shade per sample (its value is not needed).
    vec3 d = normalize(near.xyz / near.w + vec3(0.0 * float(gl_SampleID)));
#else
    vec3 d = normalize(v_pos);
#endif
    // |t d - c|^2 = r^2 with |d| = 1: t^2 - 2 t b + |c|^2 - r^2 = 0, b = d.c. Computed the
    // robust way (Haines et al., Ray Tracing Gems ch. 7): the discriminant as r^2 minus the
    // squared distance from the centre to the ray (accurate near the silhouette, where
    // b^2 - (|c|^2 - r^2) cancels), and the near root as cc / q (no cancellation when the
    // sphere is small and far).
    float b = dot(d, v_center);
    vec3 f = v_center - b * d;
    float lf = length(f);
    float disc = (v_radius - lf) * (v_radius + lf);
    if (disc < 0.0 || b <= 0.0) {
        discard;
    }
    float lc = length(v_center);
    float cc = (lc - v_radius) * (lc + v_radius);
    float q = b + sqrt(disc);
    float t = cc / q;
    vec3 hit = d * t;
    vec4 clip = pc.view_proj * vec4(hit, 1.0);
    float depth = clip.z / clip.w;
    // In front of the near plane: not drawn (as a clipped triangle would not be).
    if (depth < 0.0) {
        discard;
    }
    gl_FragDepth = depth;
    out_accum = vec4(v_color * pc.ambient.rgb, 1.0);
    // The exact normal shades too: bound 0.
    out_albedo = vec4(v_color, 0.0);
    vec3 n = (hit - v_center) / v_radius;
    out_normal = vec4(n, pack_normal(n));
    out_position = vec4(hit, 1.0);
}
