#version 450
// Light-intensity map of transparent casters (Kim, Kim, Turk 2008): every volume face a
// receiver point counts (same depth tests as the float counter) multiplies the light reaching
// it by t^c, c = +1 or -1, t = (1 - opacity) * colour of the caster. The product over all
// faces is the product of t over every surface crossed between the point and the light.
//   multiplicative (default build): out = t or 1/t, blended dst *= src;
//   log space (LOG variant):        out = +-log(t), blended dst += src, exp() when read.
// @variant LOG LOG_SPACE
layout(push_constant) uniform Push {
    mat4 mvp;
    vec4 light;
    vec4 color; // x: +1 z-pass / -1 z-fail; yzw: t
} pc;

layout(location = 0) out vec4 out_t;

void main() {
    float c = (gl_FrontFacing ? 1.0 : -1.0) * pc.color.x;
    vec3 t = pc.color.yzw;
#ifdef LOG_SPACE
    out_t = vec4(c * log(t), 0.0);
#else
    out_t = vec4(c > 0.0 ? t : vec3(1.0) / t, 1.0);
#endif
}
