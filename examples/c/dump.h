/* The frame dump `umbrage check DIR` reads, and a minimal PNG writer. */
#ifndef UMBRAGE_C_HOST_DUMP_H
#define UMBRAGE_C_HOST_DUMP_H

#include "scene.h"
#include <stdint.h>

typedef struct DumpSample {
    uint32_t width, height;
    float *positions;           /* W*H*3, NaN for background */
    float *normals;             /* W*H*3, NaN for background */
    uint8_t **masks;            /* per light, W*H: 255 lit, 0 not, 128 background */
    uint8_t **stencils;         /* per light, W*H: the stencil after its determination */
    const float (*transforms)[16]; /* per mesh, the frame's transform (NULL: the scene's) */
} DumpSample;

int write_png(const char *path, uint32_t w, uint32_t h, uint32_t channels, const uint8_t *pixels);
int write_dump(const char *dir, const HostScene *scene, const DumpSample *sample);

#endif
