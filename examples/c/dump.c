/* The frame dump `umbrage check DIR` reads (src/reference/dump.rs describes the format), and a
 * minimal PNG writer (stored deflate blocks: no compression library). */
#include "dump.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static uint32_t crc_table[256];

static void crc_init(void) {
    uint32_t n, k, c;
    for (n = 0; n < 256; n++) {
        c = n;
        for (k = 0; k < 8; k++) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
        crc_table[n] = c;
    }
}

static uint32_t crc(uint32_t c, const uint8_t *p, size_t n) {
    size_t i;
    for (i = 0; i < n; i++) c = crc_table[(c ^ p[i]) & 0xff] ^ (c >> 8);
    return c;
}

static void be32(uint8_t *p, uint32_t v) {
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

static int chunk(FILE *f, const char *type, const uint8_t *data, uint32_t len) {
    uint8_t head[8], tail[4];
    uint32_t c;
    be32(head, len);
    memcpy(head + 4, type, 4);
    c = crc(0xffffffffu, head + 4, 4);
    c = crc(c, data, len) ^ 0xffffffffu;
    be32(tail, c);
    return fwrite(head, 1, 8, f) == 8 && (len == 0 || fwrite(data, 1, len, f) == len) && fwrite(tail, 1, 4, f) == 4 ? 0 : -1;
}

int write_png(const char *path, uint32_t w, uint32_t h, uint32_t channels, const uint8_t *pixels) {
    static const uint8_t sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
    uint8_t ihdr[13];
    size_t row = (size_t)w * channels + 1, raw_len = row * h, blocks = (raw_len + 65534) / 65535, z_len, i, o = 0;
    uint8_t *raw = malloc(raw_len), *z;
    uint32_t a = 1, b = 0, y;
    FILE *f;
    int ok;
    if (!raw) return -1;
    crc_init();
    for (y = 0; y < h; y++) {
        raw[y * row] = 0; /* filter: none */
        memcpy(raw + y * row + 1, pixels + (size_t)y * w * channels, (size_t)w * channels);
    }
    z_len = 2 + raw_len + 5 * (blocks ? blocks : 1) + 4;
    z = malloc(z_len);
    if (!z) {
        free(raw);
        return -1;
    }
    z[o++] = 0x78;
    z[o++] = 0x01;
    for (i = 0; i < raw_len || (i == 0 && raw_len == 0); i += 65535) {
        size_t n = raw_len - i < 65535 ? raw_len - i : 65535;
        z[o++] = (uint8_t)(i + n >= raw_len);
        z[o++] = (uint8_t)n;
        z[o++] = (uint8_t)(n >> 8);
        z[o++] = (uint8_t)~n;
        z[o++] = (uint8_t)(~n >> 8);
        memcpy(z + o, raw + i, n);
        o += n;
        if (raw_len == 0) break;
    }
    for (i = 0; i < raw_len; i++) {
        a = (a + raw[i]) % 65521;
        b = (b + a) % 65521;
    }
    be32(z + o, (b << 16) | a);
    o += 4;
    be32(ihdr, w);
    be32(ihdr + 4, h);
    ihdr[8] = 8;
    ihdr[9] = channels == 1 ? 0 : channels == 3 ? 2 : 6;
    ihdr[10] = ihdr[11] = ihdr[12] = 0;
    f = fopen(path, "wb");
    ok = f && fwrite(sig, 1, 8, f) == 8 && chunk(f, "IHDR", ihdr, 13) == 0 && chunk(f, "IDAT", z, (uint32_t)o) == 0 &&
         chunk(f, "IEND", NULL, 0) == 0;
    if (f && fclose(f) != 0) ok = 0;
    free(raw);
    free(z);
    if (!ok) fprintf(stderr, "cannot write %s: %s\n", path, strerror(errno));
    return ok ? 0 : -1;
}

static int make_dir(const char *path) {
    char tmp[1024];
    size_t i, n = strlen(path);
    if (n >= sizeof tmp) return -1;
    memcpy(tmp, path, n + 1);
    for (i = 1; i <= n; i++) {
        if (tmp[i] == '/' || tmp[i] == 0) {
            char c = tmp[i];
            tmp[i] = 0;
            if (mkdir(tmp, 0777) != 0 && errno != EEXIST) {
                fprintf(stderr, "cannot create %s: %s\n", tmp, strerror(errno));
                return -1;
            }
            tmp[i] = c;
        }
    }
    return 0;
}

static void world_point(const float *m, const float *p, double out[3]) {
    /* as glam's DMat4::transform_point3 on the f32 matrix widened to f64 */
    int r;
    for (r = 0; r < 3; r++)
        out[r] = (double)m[r] * p[0] + (double)m[4 + r] * p[1] + (double)m[8 + r] * p[2] + (double)m[12 + r];
}

int write_dump(const char *dir, const HostScene *s, const DumpSample *d) {
    char path[1200];
    FILE *f;
    uint32_t i, k, n = d->width * d->height;
    static const char *kinds[3] = {"point", "spot", "directional"};
    if (make_dir(dir) != 0) return -1;

    snprintf(path, sizeof path, "%s/frame.json", dir);
    if (!(f = fopen(path, "w"))) return -1;
    fprintf(f, "{\n  \"width\": %u,\n  \"height\": %u,\n  \"camera_pos\": [%.9g, %.9g, %.9g],\n  \"lights\": [", d->width, d->height,
            (double)s->eye[0], (double)s->eye[1], (double)s->eye[2]);
    for (k = 0; k < s->light_count; k++) {
        const HostLight *l = &s->lights[k];
        double hp[4];
        if (l->kind == 2) {
            /* as glam's Vec3::normalize in f32 */
            float len = sqrtf((l->direction[0] * l->direction[0] + l->direction[1] * l->direction[1]) + l->direction[2] * l->direction[2]);
            float recip = 1.0f / len;
            for (i = 0; i < 3; i++) hp[i] = -(double)(l->direction[i] * recip);
            hp[3] = 0;
        } else {
            for (i = 0; i < 3; i++) hp[i] = l->position[i];
            hp[3] = 1;
        }
        fprintf(f, "%s\n    {\"position\": [%.9g, %.9g, %.9g, %.9g], \"kind\": \"%s\", \"direction\": [%.9g, %.9g, %.9g]", k ? "," : "",
                hp[0], hp[1], hp[2], hp[3], kinds[l->kind], (double)l->direction[0], (double)l->direction[1], (double)l->direction[2]);
        if (l->kind == 1) fprintf(f, ", \"cone_deg\": %.9g", (double)l->cone_deg);
        if (l->radius != 0.0f) fprintf(f, ", \"radius\": %.9g", (double)l->radius);
        fprintf(f, "}");
    }
    fprintf(f, "\n  ]\n}\n");
    if (fclose(f) != 0) return -1;

    /* world.obj: every opaque shadow-casting triangle in world space, as the frame drew it */
    snprintf(path, sizeof path, "%s/world.obj", dir);
    if (!(f = fopen(path, "w"))) return -1;
    fprintf(f, "# umbrage frame dump: shadow-casting triangles, world space\n");
    {
        uint32_t faces = 0, mi, t, c;
        for (mi = 0; mi < s->mesh_count; mi++) {
            const HostMesh *m = &s->meshes[mi];
            if (!m->casts_shadow || m->opacity < 1.0f) continue;
            for (t = 0; t < m->triangle_count; t++)
                for (c = 0; c < 3; c++) {
                    double w[3];
                    world_point(d->transforms ? d->transforms[mi] : m->transform, &m->positions[3 * m->triangles[3 * t + c]], w);
                    fprintf(f, "v %.9g %.9g %.9g\n", (double)(float)w[0], (double)(float)w[1], (double)(float)w[2]);
                }
            faces += m->triangle_count;
        }
        for (t = 0; t < faces; t++) fprintf(f, "f %u %u %u\n", 3 * t + 1, 3 * t + 2, 3 * t + 3);
    }
    if (fclose(f) != 0) return -1;

    snprintf(path, sizeof path, "%s/positions.f32", dir);
    if (!(f = fopen(path, "wb")) || fwrite(d->positions, sizeof(float), 3 * (size_t)n, f) != 3 * (size_t)n || fclose(f) != 0) return -1;
    snprintf(path, sizeof path, "%s/normals.f32", dir);
    if (!(f = fopen(path, "wb")) || fwrite(d->normals, sizeof(float), 3 * (size_t)n, f) != 3 * (size_t)n || fclose(f) != 0) return -1;
    for (k = 0; k < s->light_count; k++) {
        snprintf(path, sizeof path, "%s/shadow_%u.png", dir, k);
        if (write_png(path, d->width, d->height, 1, d->masks[k]) != 0) return -1;
        snprintf(path, sizeof path, "%s/stencil_%u.png", dir, k);
        if (write_png(path, d->width, d->height, 1, d->stencils[k]) != 0) return -1;
    }
    return 0;
}
