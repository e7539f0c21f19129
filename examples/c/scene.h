/* The C host's scene: what `umbrage export-scene NAME|FILE OUT` writes (docs/c-api.md). */
#ifndef UMBRAGE_C_HOST_SCENE_H
#define UMBRAGE_C_HOST_SCENE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct HostMesh {
    char name[64];
    int casts_shadow;
    float opacity;
    float transform[16]; /* object -> world, column-major */
    uint32_t vertex_count;
    uint32_t triangle_count;
    float *positions;    /* vertex_count * 3 */
    uint32_t *triangles; /* triangle_count * 3 */
} HostMesh;

typedef struct HostLight {
    int kind; /* 0 point, 1 spot, 2 directional (UmbrageLightKind's values) */
    float position[3];
    float direction[3];
    float cone_deg;
    float radius; /* 0: unbounded */
} HostLight;

typedef struct HostScene {
    float eye[3], target[3], up[3];
    float fov_y_deg, near_plane;
    HostLight *lights;
    uint32_t light_count;
    HostMesh *meshes;
    uint32_t mesh_count;
    uint32_t sphere_count;
} HostScene;

/* Reads an exported scene; 0 on success, else prints why and returns -1. */
int scene_load(const char *path, HostScene *out);
void scene_free(HostScene *s);

#ifdef __cplusplus
}
#endif

#endif
