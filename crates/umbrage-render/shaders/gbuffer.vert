#version 450
// Scene geometry, baked to world space relative to an anchor (the eye at creation) in f64;
// camera-relative rendering keeps precision for scenes far from the origin. Flat face normals
// (the shadows' facing), and smooth ones with their terminator bound (the shading).
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec3 in_color;
// The smooth shading normal and its terminator bound (geom::shading::corner_normals).
layout(location = 10) in vec3 in_smooth;
layout(location = 11) in float in_bound;
// Per-mesh placement (instance rate, binding 1): rows of the affine map from the baked
// anchor-relative positions to eye-relative ones, and of the normals' linear map. Exactly the
// identity (and zero translation) for a mesh that has not moved with the eye at the anchor,
// so static frames are bit for bit what the baked positions give.
layout(location = 4) in vec4 in_xf0;
layout(location = 5) in vec4 in_xf1;
layout(location = 6) in vec4 in_xf2;
layout(location = 7) in vec4 in_n0;
layout(location = 8) in vec4 in_n1;
layout(location = 9) in vec4 in_n2;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 ambient;
} pc;

layout(location = 0) out vec3 v_pos;
layout(location = 1) flat out vec3 v_normal;
layout(location = 2) flat out vec3 v_color;
layout(location = 3) out vec3 v_smooth;
layout(location = 4) out float v_bound;

void main() {
    vec4 p = vec4(in_pos, 1.0);
    vec3 pos = vec3(dot(in_xf0, p), dot(in_xf1, p), dot(in_xf2, p));
    v_pos = pos;
    v_normal = vec3(dot(in_n0.xyz, in_normal), dot(in_n1.xyz, in_normal), dot(in_n2.xyz, in_normal));
    v_color = in_color;
    v_smooth = vec3(dot(in_n0.xyz, in_smooth), dot(in_n1.xyz, in_smooth), dot(in_n2.xyz, in_smooth));
    v_bound = in_bound;
    gl_Position = pc.view_proj * vec4(pos, 1.0);
}
