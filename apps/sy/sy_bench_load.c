/* sy_bench_load.c — `sy bench load` (formats, issue 6): tinygltf's parse against the whole
 * sy_gltf_load, and the peak RSS of a load, for the glTF samples and a generated .glb; also writes
 * the generated .glb for sy bench memory (sy_bench_write_grid_glb; see sy_bench.h). The Assimp part
 * (issue 34): a generated OBJ (text, written here) and the same grid as binary FBX (Assimp's own
 * exporter), sy_assimp_load against Assimp's own import as `assimp info` makes it, each in a forked
 * child: wall time and peak RSS against the bytes of the scene the load made. */
#include "sy_bench.h"

#include "sy_assimp.h"
#include "sy_file.h"
#include "sy_gltf.h"
#include "sy_gltf_shim.h"

#include <dirent.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static int cmp_cstr(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }
/* Peak RSS growth (KiB) of one sy_gltf_load in a forked child: the child's high-water mark minus
 * its resident size at the start, so the parent's own footprint does not count. -1 on failure. */
static long load_peak_kib(const char *path)
{
    int fds[2];
    if (pipe(fds) != 0) return -1;
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return -1;
    }
    if (pid == 0) {
        close(fds[0]);
        long base = sy_bench_rss_now_kib(), peak = -1;
        sy_scene *s;
        sy_gltf_info info = {0};
        if (sy_scene_create(&s, NULL) == SY_OK && sy_gltf_load(path, s, NULL, &info, NULL) == SY_OK) {
            struct rusage ru;
            getrusage(RUSAGE_SELF, &ru);
            peak = ru.ru_maxrss - base;
        }
        ssize_t w = write(fds[1], &peak, sizeof peak);
        _exit(w == (ssize_t)sizeof peak ? 0 : 1);
    }
    close(fds[1]);
    long peak = -1;
    if (read(fds[0], &peak, sizeof peak) != (ssize_t)sizeof peak) peak = -1;
    close(fds[0]);
    int status;
    waitpid(pid, &status, 0);
    return peak;
}

/* Bytes the load reads: the file plus, for .gltf, the other files of its directory (buffers,
 * images; a sample variant directory holds exactly one model). */
static double input_bytes(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return 0;
    double total = (double)st.st_size;
    size_t n = strlen(path);
    if (n < 5 || strcmp(path + n - 5, ".gltf") != 0) return total;
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash) *slash = '\0';
    else snprintf(dir, sizeof dir, ".");
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) {
        char p[8192];
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        if (strcmp(p, path) != 0 && e->d_name[0] != '.' && stat(p, &st) == 0 && S_ISREG(st.st_mode))
            total += (double)st.st_size;
    }
    if (d) closedir(d);
    return total;
}

static sy_result bench_one_load(const char *label, const char *path, uint32_t repeats, sy_error *err)
{
    double *tp = malloc(repeats * sizeof(double)), *tl = malloc(repeats * sizeof(double));
    sy_result r = (tp && tl) ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench load: out of memory");
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash) slash[1] = '\0';
    else dir[0] = '\0';
    size_t n = strlen(path);
    bool binary = n > 4 && !strcmp(path + n - 4, ".glb");
    sy_gltf_shim_limits lim = {.max_file_bytes = (size_t)2 << 30, .max_image_pixels = (uint64_t)1 << 26};
    uint32_t tris = 0;
    for (uint32_t k = 0; r == SY_OK && k < repeats; k++) {
        /* tinygltf alone: read + parse (buffers, image decoding), nothing else */
        double t0 = sy_time_now();
        void *bytes = NULL;
        size_t size = 0;
        r = sy_file_read_all(path, (size_t)2 << 30, &bytes, &size, err);
        if (r == SY_OK) r = sy_gltf_shim_parse_only(bytes, size, binary, dir, &lim, err);
        free(bytes);
        tp[k] = sy_time_now() - t0;
        if (r) break;
        /* the whole loader: read, parse, validate, convert, create the scene objects */
        sy_scene *s = NULL;
        sy_gltf_info info = {0};
        if ((r = sy_scene_create(&s, err))) break;
        t0 = sy_time_now();
        r = sy_gltf_load(path, s, NULL, &info, err);
        tl[k] = sy_time_now() - t0;
        tris = info.counts.triangles;
        sy_gltf_info_free(&info);
        sy_scene_destroy(s);
    }
    if (r == SY_OK) {
        qsort(tp, repeats, sizeof(double), sy_bench_cmp_double);
        qsort(tl, repeats, sizeof(double), sy_bench_cmp_double);
        double parse = tp[repeats / 2], load = tl[repeats / 2], bytes = input_bytes(path);
        long peak = load_peak_kib(path);
        printf("%-34s %9.2f %9u %10.2f %10.2f %7.2fx %9.1f %7.2fx\n", label, bytes / 1048576.0, tris, parse * 1e3,
               load * 1e3, parse > 0 ? load / parse : 0.0, peak >= 0 ? (double)peak / 1024.0 : -1.0,
               peak >= 0 && bytes > 0 ? (double)peak * 1024.0 / bytes : 0.0);
        fflush(stdout);
    } else {
        sy_error_prefix(err, "%s", label);
    }
    free(tp);
    free(tl);
    return r;
}

/* A .glb with a (grid + 1)^2-vertex grid of 2 * grid^2 triangles: POSITION, NORMAL, TEXCOORD_0,
 * uint32 indices; written through sy_atomic_file. */
sy_result sy_bench_write_grid_glb(const char *path, uint32_t grid, sy_error *err)
{
    size_t nv = (size_t)(grid + 1) * (grid + 1), ni = (size_t)grid * grid * 6;
    size_t pos_b = nv * 12, nrm_b = nv * 12, uv_b = nv * 8, idx_b = ni * 4, bin = pos_b + nrm_b + uv_b + idx_b;
    uint8_t *b = malloc(bin);
    if (!b) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench load: out of memory");
    float *pos = (float *)b, *nrm = (float *)(b + pos_b), *uv = (float *)(b + pos_b + nrm_b);
    uint32_t *idx = (uint32_t *)(b + pos_b + nrm_b + uv_b);
    for (uint32_t y = 0; y <= grid; y++)
        for (uint32_t x = 0; x <= grid; x++) {
            size_t v = (size_t)y * (grid + 1) + x;
            float fx = (float)x / (float)grid, fy = (float)y / (float)grid;
            pos[3 * v] = fx; pos[3 * v + 1] = 0.05f * sinf(12.0f * fx) * cosf(9.0f * fy); pos[3 * v + 2] = fy;
            nrm[3 * v] = 0; nrm[3 * v + 1] = 1; nrm[3 * v + 2] = 0;
            uv[2 * v] = fx; uv[2 * v + 1] = fy;
        }
    size_t k = 0;
    for (uint32_t y = 0; y < grid; y++)
        for (uint32_t x = 0; x < grid; x++) {
            uint32_t a = y * (grid + 1) + x, c = a + grid + 1;
            idx[k++] = a; idx[k++] = c; idx[k++] = a + 1;
            idx[k++] = a + 1; idx[k++] = c; idx[k++] = c + 1;
        }
    char json[2048];
    int jn = snprintf(json, sizeof json,
        "{\"asset\":{\"version\":\"2.0\",\"generator\":\"sy bench load\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,"
        "\"TEXCOORD_0\":2},\"indices\":3}]}],\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":["
        "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
        "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\",\"min\":[0,-0.05,0],"
        "\"max\":[1,0.05,1]},{\"bufferView\":1,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC2\"},"
        "{\"bufferView\":3,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"}]}",
        bin, pos_b, pos_b, nrm_b, pos_b + nrm_b, uv_b, pos_b + nrm_b + uv_b, idx_b, nv, nv, nv, ni);
    while (jn % 4) json[jn++] = ' ';
    uint32_t hdr[5] = {0x46546C67u, 2, (uint32_t)(12 + 8 + jn + 8 + bin), (uint32_t)jn, 0x4E4F534Au};
    uint32_t bhdr[2] = {(uint32_t)bin, 0x004E4942u};
    sy_atomic_file af = {0};
    sy_result r = sy_atomic_file_begin(path, &af, err);
    if (r == SY_OK) {
        if (fwrite(hdr, 4, 5, af.fp) != 5 || fwrite(json, 1, (size_t)jn, af.fp) != (size_t)jn ||
            fwrite(bhdr, 4, 2, af.fp) != 2 || fwrite(b, 1, bin, af.fp) != bin) {
            sy_atomic_file_abort(&af);
            r = sy_error_set(err, SY_ERR_IO, "%s: write failed", path);
        } else {
            r = sy_atomic_file_commit(&af, err);
        }
    }
    free(b);
    return r;
}

/* >>assimp (issue 34) ------------------------------------------------------------------------- */

/* What one forked child measured. */
typedef struct asp_run {
    int ok;
    char message[sizeof(((sy_error *)0)->message)];
    double seconds, scene_bytes; /* the call's wall time; the mesh and texture bytes of the made scene */
    long peak_kib;               /* RSS high-water mark less the RSS at the start */
    uint32_t meshes, tris;
} asp_run;

/* Bytes the scene's meshes and textures hold (blob payloads). */
static double scene_bytes(sy_scene *s)
{
    double b = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_MESH, 0); id; id = sy_scene_next(s, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_object_get(s, SY_TYPE_MESH, id);
        for (uint32_t i = 0; m && i < m->primitives.count; ++i) {
            const sy_primitive *p = &m->primitives.items[i];
            b += (double)(sy_blob_size(p->positions) + sy_blob_size(p->normals) + sy_blob_size(p->tangents) +
                          sy_blob_size(p->texcoords0) + sy_blob_size(p->texcoords1) + sy_blob_size(p->colors) +
                          sy_blob_size(p->indices));
        }
    }
    for (uint32_t id = sy_scene_next(s, SY_TYPE_TEXTURE, 0); id; id = sy_scene_next(s, SY_TYPE_TEXTURE, id)) {
        const sy_texture_data *t = sy_object_get(s, SY_TYPE_TEXTURE, id);
        if (t) b += (double)sy_blob_size(t->pixels);
    }
    return b;
}

/* How a forked child loads: Assimp's own import, sy_assimp_load as sy render makes it (in the
 * import process), or sy_assimp_load in the child itself (in_process: the import process's cost). */
enum { ASP_REFERENCE, ASP_SY, ASP_SY_IN_PROCESS };

/* One load in a forked child. */
static void asp_child(const char *path, int how, asp_run *o)
{
    bool reference = how == ASP_REFERENCE;
    sy_error e = {0};
    memset(o, 0, sizeof *o);
    long base = sy_bench_rss_now_kib();
    sy_result r;
    double t0 = sy_time_now();
    if (reference) {
        sy_assimp_counts c;
        r = sy_assimp_reference_import(path, &c, &e);
        o->seconds = sy_time_now() - t0;
        o->meshes = c.meshes;
        o->tris = c.triangles;
    } else {
        sy_scene *s = NULL;
        sy_assimp_info info = {0};
        r = sy_scene_create(&s, &e);
        t0 = sy_time_now();
        sy_assimp_options ao = {.in_process = how == ASP_SY_IN_PROCESS};
        if (r == SY_OK) r = sy_assimp_load(path, s, &ao, &info, &e);
        o->seconds = sy_time_now() - t0;
        o->meshes = info.counts.meshes;
        o->tris = info.counts.triangles;
        if (r == SY_OK) o->scene_bytes = scene_bytes(s);
        sy_assimp_info_free(&info);
        /* the scene stays: the peak is read below, destroying it frees nothing the peak counted */
    }
    struct rusage ru, rc;
    getrusage(RUSAGE_SELF, &ru);
    o->peak_kib = ru.ru_maxrss - base;
    /* the import process (a fork of this one, so the same base) peaks on its own */
    if (getrusage(RUSAGE_CHILDREN, &rc) == 0 && rc.ru_maxrss - base > o->peak_kib) o->peak_kib = rc.ru_maxrss - base;
    o->ok = r == SY_OK;
    snprintf(o->message, sizeof o->message, "%s", e.message);
}

static sy_result asp_run_forked(const char *path, int how, asp_run *o, sy_error *err)
{
    int fds[2];
    if (pipe(fds) != 0) return sy_error_set(err, SY_ERR_IO, "bench load: pipe failed");
    fflush(stdout);
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return sy_error_set(err, SY_ERR_IO, "bench load: fork failed");
    }
    if (pid == 0) {
        close(fds[0]);
        asp_run run;
        asp_child(path, how, &run);
        ssize_t w = write(fds[1], &run, sizeof run);
        _exit(w == (ssize_t)sizeof run ? 0 : 1);
    }
    close(fds[1]);
    ssize_t got = read(fds[0], o, sizeof *o);
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (got != (ssize_t)sizeof *o)
        return sy_error_set(err, SY_ERR_IO, "%s: the measuring child died (status %d)", path, status);
    if (!o->ok) return sy_error_set(err, SY_ERR_PARSE, "%s", o->message);
    return SY_OK;
}

static int cmp_run_seconds(const void *a, const void *b)
{
    double x = ((const asp_run *)a)->seconds, y = ((const asp_run *)b)->seconds;
    return x < y ? -1 : x > y;
}

/* Median of `repeats` forked loads each way; one row. */
static sy_result bench_assimp_one(const char *label, const char *path, uint32_t repeats, sy_error *err)
{
    asp_run *runs = calloc((size_t)repeats * 3, sizeof *runs);
    if (!runs) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench load: out of memory");
    sy_result r = SY_OK;
    for (uint32_t k = 0; k < repeats && r == SY_OK; ++k) { /* interleaved: the same machine state for each */
        r = asp_run_forked(path, ASP_REFERENCE, &runs[k], err);
        if (r == SY_OK) r = asp_run_forked(path, ASP_SY, &runs[repeats + k], err);
        if (r == SY_OK) r = asp_run_forked(path, ASP_SY_IN_PROCESS, &runs[2 * repeats + k], err);
    }
    if (r == SY_OK) {
        for (int m = 0; m < 3; ++m) qsort(runs + m * repeats, repeats, sizeof *runs, cmp_run_seconds);
        const asp_run *a = &runs[repeats / 2], *s = &runs[repeats + repeats / 2], *h = &runs[2 * repeats + repeats / 2];
        struct stat st;
        double file = stat(path, &st) == 0 ? (double)st.st_size : 0;
        printf("%-24s %8.2f %9u %9u %10.1f %10.1f %7.2fx %9.1f %7.2fx %9.1f %9.1f %9.1f %7.2fx\n", label, file / 1048576.0,
               a->tris, s->tris, a->seconds * 1e3, s->seconds * 1e3, a->seconds > 0 ? s->seconds / a->seconds : 0.0,
               h->seconds * 1e3, h->seconds > 0 ? s->seconds / h->seconds : 0.0, (double)a->peak_kib / 1024.0,
               (double)s->peak_kib / 1024.0, s->scene_bytes / 1048576.0,
               s->scene_bytes > 0 ? (double)s->peak_kib * 1024.0 / s->scene_bytes : 0.0);
        fflush(stdout);
    } else {
        sy_error_prefix(err, "%s", label);
    }
    free(runs);
    return r;
}

/* A text OBJ of the grid sy_bench_write_grid_glb makes: v, vt, vn per grid vertex, two triangles
 * per cell (f a/a/a b/b/b c/c/c). */
static sy_result write_grid_obj(const char *path, uint32_t grid, sy_error *err)
{
    sy_atomic_file af = {0};
    sy_result r = sy_atomic_file_begin(path, &af, err);
    if (r) return r;
    bool ok = fprintf(af.fp, "# sy bench load: %u x %u grid, %u triangles\no grid\n", grid, grid, 2 * grid * grid) > 0;
    for (uint32_t y = 0; ok && y <= grid; y++)
        for (uint32_t x = 0; ok && x <= grid; x++) {
            float fx = (float)x / (float)grid, fy = (float)y / (float)grid;
            ok = fprintf(af.fp, "v %.6g %.6g %.6g\nvt %.6g %.6g\nvn 0 1 0\n", fx, 0.05f * sinf(12.0f * fx) * cosf(9.0f * fy),
                         fy, fx, fy) > 0;
        }
    for (uint32_t y = 0; ok && y < grid; y++)
        for (uint32_t x = 0; ok && x < grid; x++) {
            uint32_t a = y * (grid + 1) + x + 1, c = a + grid + 1; /* 1-based */
            ok = fprintf(af.fp, "f %u/%u/%u %u/%u/%u %u/%u/%u\nf %u/%u/%u %u/%u/%u %u/%u/%u\n", a, a, a, c, c, c, a + 1,
                         a + 1, a + 1, a + 1, a + 1, a + 1, c, c, c, c + 1, c + 1, c + 1) > 0;
        }
    if (!ok) {
        sy_atomic_file_abort(&af);
        return sy_error_set(err, SY_ERR_IO, "%s: write failed", path);
    }
    return sy_atomic_file_commit(&af, err);
}

/* The Assimp part: the generated grid as OBJ and as binary FBX. */
static sy_result bench_assimp(uint32_t tris, uint32_t repeats, sy_error *err)
{
    printf("\nAssimp formats: median of %u loads each way, each in a forked child; 'assimp' = Assimp's own import as\n"
           "`assimp info` makes it (aiProcessPreset_TargetRealtime_MaxQuality), 'sy load' = sy_assimp_load into a fresh\n"
           "scene (as sy render: in the import process), 'in proc' = the same load in the child itself (in_process),\n"
           "'iso' = sy load / in proc (what the import process costs); peak = RSS growth of the child or of its\n"
           "import process, whichever is larger; scene = the mesh and texture bytes the load made\n\n",
           (unsigned)repeats);
    printf("%-24s %8s %9s %9s %10s %10s %8s %9s %8s %9s %9s %9s %8s\n", "model", "file MB", "tris", "sy tris", "assimp",
           "sy load", "ratio", "in proc", "iso", "assimp pk", "sy peak", "scene MB", "pk/scene");
    printf("%-24s %8s %9s %9s %10s %10s %8s %9s %8s %9s %9s %9s %8s\n", "", "", "", "", "ms", "ms", "", "ms", "", "MB", "MB", "",
           "");
    char dir[] = "/tmp/sy_bench_load_assimp_XXXXXX", obj[128], fbx[128];
    if (!mkdtemp(dir)) return sy_error_set(err, SY_ERR_IO, "bench load: cannot create a temporary directory");
    snprintf(obj, sizeof obj, "%s/grid.obj", dir);
    snprintf(fbx, sizeof fbx, "%s/grid.fbx", dir);
    uint32_t grid = (uint32_t)ceil(sqrt((double)tris / 2.0));
    char label[64];
    sy_result r = write_grid_obj(obj, grid, err);
    if (r == SY_OK) {
        snprintf(label, sizeof label, "grid OBJ (%u tris)", 2 * grid * grid);
        r = bench_assimp_one(label, obj, repeats, err);
    }
    /* binary FBX first; Assimp 5.2's binary exporter leaves out the null records that end each node
     * list (assimp/assimp#4686), so its own reader refuses the file ("block offset is out of range"):
     * then the same grid as ASCII FBX, which it writes whole */
    const char *kind = "binary";
    sy_error e2 = {0};
    if (r == SY_OK) r = sy_assimp_export(obj, "fbx", fbx, err);
    if (r == SY_OK && sy_assimp_reference_import(fbx, NULL, &e2) != SY_OK) {
        printf("(Assimp cannot read its own binary FBX export: %s; ASCII FBX instead)\n", e2.message);
        kind = "ASCII";
        r = sy_assimp_export(obj, "fbxa", fbx, err);
    }
    if (r == SY_OK) {
        snprintf(label, sizeof label, "grid %s FBX (%u tris)", kind, 2 * grid * grid);
        r = bench_assimp_one(label, fbx, repeats, err);
    }
    unlink(obj);
    unlink(fbx);
    rmdir(dir);
    return r;
}

sy_result sy_bench_load(const char *data_dir, uint32_t tris, uint32_t repeats, sy_error *err)
{
    printf("sy bench load: median of %u loads; 'tinygltf' = read + tinygltf parse alone (buffers, images decoded),\n"
           "'sy load' = sy_gltf_load into a fresh scene; peak = RSS growth of one load in a forked child\n\n",
           (unsigned)repeats);
    printf("%-34s %9s %9s %10s %10s %8s %9s %8s\n", "model", "file MB", "tris", "tinygltf", "sy load", "ratio",
           "peak MB", "peak/file");
    printf("%-34s %9s %9s %10s %10s %8s %9s %8s\n", "", "", "", "ms", "ms", "", "", "");
    sy_result r = SY_OK;
    DIR *d = opendir(data_dir);
    if (!d) {
        printf("(no sample models: %s not found)\n", data_dir);
    } else {
        char **names = NULL;
        size_t count = 0, cap = 0;
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            if (e->d_name[0] == '.' || e->d_name[0] == '_') continue;
            if (count == cap) {
                cap = cap ? cap * 2 : 64;
                char **nn = realloc(names, cap * sizeof *nn);
                if (!nn) break;
                names = nn;
            }
            names[count] = strdup(e->d_name);
            if (names[count]) count++;
        }
        closedir(d);
        qsort(names, count, sizeof *names, cmp_cstr);
        for (size_t i = 0; i < count && r == SY_OK; i++) {
            /* one variant per model: the binary one when present */
            static const char *const variants[][2] = {{"glTF-Binary", ".glb"}, {"glTF", ".gltf"}};
            char path[4096];
            bool found = false;
            for (int v = 0; v < 2 && !found; v++) {
                snprintf(path, sizeof path, "%s/%s/%s/%s%s", data_dir, names[i], variants[v][0], names[i], variants[v][1]);
                struct stat st;
                found = stat(path, &st) == 0;
            }
            if (found) r = bench_one_load(names[i], path, repeats, err);
        }
        for (size_t i = 0; i < count; i++) free(names[i]);
        free(names);
    }
    if (r != SY_OK) return r;
    /* generated model */
    char dir[] = "/tmp/sy_bench_load_XXXXXX", path[128];
    if (!mkdtemp(dir)) return sy_error_set(err, SY_ERR_IO, "bench load: cannot create a temporary directory");
    snprintf(path, sizeof path, "%s/grid.glb", dir);
    uint32_t grid = (uint32_t)ceil(sqrt((double)tris / 2.0));
    char label[64];
    snprintf(label, sizeof label, "generated grid (%u tris)", 2 * grid * grid);
    r = sy_bench_write_grid_glb(path, grid, err);
    if (r == SY_OK) r = bench_one_load(label, path, repeats, err);
    unlink(path);
    rmdir(dir);
    if (r == SY_OK) r = bench_assimp(tris, repeats, err);
    return r;
}
