/* Reads the flat scene format `umbrage export-scene` writes (docs/c-api.md). */
#include "scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(FILE *f, const char *path, const char *what) {
    fprintf(stderr, "scene %s: %s\n", path, what);
    if (f) fclose(f);
    return -1;
}

int scene_load(const char *path, HostScene *s) {
    char key[32];
    int version = 0;
    uint32_t cap_l = 0, cap_m = 0;
    FILE *f = fopen(path, "r");
    memset(s, 0, sizeof *s);
    if (!f) return fail(NULL, path, "cannot open (write it with `umbrage export-scene NAME FILE`)");
    if (fscanf(f, "%31s %d", key, &version) != 2 || strcmp(key, "umbrage-scene") != 0 || version != 1)
        return fail(f, path, "not an umbrage-scene 1 file");
    while (fscanf(f, "%31s", key) == 1) {
        if (strcmp(key, "end") == 0) {
            fclose(f);
            return 0;
        } else if (strcmp(key, "camera") == 0) {
            if (fscanf(f, "%f %f %f %f %f %f %f %f %f %f %f", &s->eye[0], &s->eye[1], &s->eye[2], &s->target[0], &s->target[1],
                       &s->target[2], &s->up[0], &s->up[1], &s->up[2], &s->fov_y_deg, &s->near_plane) != 11)
                return fail(f, path, "bad camera line");
        } else if (strcmp(key, "light") == 0) {
            HostLight *l;
            char kind[16];
            if (s->light_count == cap_l) {
                cap_l = cap_l ? 2 * cap_l : 4;
                s->lights = realloc(s->lights, cap_l * sizeof *s->lights);
                if (!s->lights) return fail(f, path, "out of memory");
            }
            l = &s->lights[s->light_count++];
            if (fscanf(f, "%15s %f %f %f %f %f %f %f %f", kind, &l->position[0], &l->position[1], &l->position[2], &l->direction[0],
                       &l->direction[1], &l->direction[2], &l->cone_deg, &l->radius) != 9)
                return fail(f, path, "bad light line");
            l->kind = strcmp(kind, "spot") == 0 ? 1 : strcmp(kind, "directional") == 0 ? 2 : 0;
        } else if (strcmp(key, "mesh") == 0) {
            HostMesh *m;
            uint32_t i;
            if (s->mesh_count == cap_m) {
                cap_m = cap_m ? 2 * cap_m : 4;
                s->meshes = realloc(s->meshes, cap_m * sizeof *s->meshes);
                if (!s->meshes) return fail(f, path, "out of memory");
            }
            m = &s->meshes[s->mesh_count++];
            memset(m, 0, sizeof *m);
            if (fscanf(f, "%63s %d %f %u %u", m->name, &m->casts_shadow, &m->opacity, &m->vertex_count, &m->triangle_count) != 5)
                return fail(f, path, "bad mesh line");
            if (fscanf(f, "%31s", key) != 1 || strcmp(key, "transform") != 0) return fail(f, path, "a mesh without its transform");
            for (i = 0; i < 16; i++)
                if (fscanf(f, "%f", &m->transform[i]) != 1) return fail(f, path, "bad transform");
            m->positions = malloc((size_t)m->vertex_count * 3 * sizeof(float) + 1);
            m->triangles = malloc((size_t)m->triangle_count * 3 * sizeof(uint32_t) + 1);
            if (!m->positions || !m->triangles) return fail(f, path, "out of memory");
            for (i = 0; i < m->vertex_count; i++)
                if (fscanf(f, " v %f %f %f", &m->positions[3 * i], &m->positions[3 * i + 1], &m->positions[3 * i + 2]) != 3)
                    return fail(f, path, "bad vertex");
            for (i = 0; i < m->triangle_count; i++) {
                uint32_t *t = &m->triangles[3 * i];
                if (fscanf(f, " t %u %u %u", &t[0], &t[1], &t[2]) != 3) return fail(f, path, "bad triangle");
                if (t[0] >= m->vertex_count || t[1] >= m->vertex_count || t[2] >= m->vertex_count)
                    return fail(f, path, "triangle index out of range");
            }
        } else if (strcmp(key, "sphere") == 0) {
            float c[5];
            if (fscanf(f, "%f %f %f %f %f", &c[0], &c[1], &c[2], &c[3], &c[4]) != 5) return fail(f, path, "bad sphere line");
            s->sphere_count++;
        } else {
            return fail(f, path, "unknown record");
        }
    }
    return fail(f, path, "no `end` line");
}

void scene_free(HostScene *s) {
    uint32_t i;
    for (i = 0; i < s->mesh_count; i++) {
        free(s->meshes[i].positions);
        free(s->meshes[i].triangles);
    }
    free(s->meshes);
    free(s->lights);
    memset(s, 0, sizeof *s);
}
