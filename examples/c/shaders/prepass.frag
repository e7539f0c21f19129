#version 450
layout(location = 0) flat in vec4 v_plane;
layout(location = 0) out vec4 out_plane;
void main() { out_plane = v_plane; }
