#version 450
// The host's pre-pass: object-space positions through the caster's own MVP (composed in f64
// exactly as the pass composes it, so the volumes' caps land on these depths), and the
// triangle's world normal and plane offset from the eye, flat.
layout(push_constant) uniform Push { mat4 mvp; } pc;
layout(location = 0) in vec3 position;
layout(location = 1) in vec4 plane;
layout(location = 0) flat out vec4 v_plane;
void main() {
    v_plane = plane;
    gl_Position = pc.mvp * vec4(position, 1.0);
}
