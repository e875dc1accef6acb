/* test_log.c — the log callback (sy_log.h): a callback receives level, module, item and message;
 * the level filter drops what is less severe (errors always pass); the default prints
 * "sy: LEVEL: [item: ]message" on stderr; long messages arrive whole; calls from several threads
 * are serialised (a plain counter in the callback stays exact); sy_log inside the callback does not
 * deadlock. */
#include "../support/sy_check.h"
#include "sy_log.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct seen {
    int calls;
    sy_log_level level;
    char module[64], item[64], message[4096];
    bool item_null;
} seen;

static void record(void *user, sy_log_level level, const char *module, const char *item, const char *message)
{
    seen *s = user;
    s->calls++;
    s->level = level;
    snprintf(s->module, sizeof s->module, "%s", module);
    s->item_null = item == NULL;
    snprintf(s->item, sizeof s->item, "%s", item ? item : "");
    snprintf(s->message, sizeof s->message, "%s", message);
}

static int test_callback_fields(void)
{
    seen s = {0};
    sy_log_set_level(SY_LOG_NOTE);
    sy_log_set_callback(record, &s);
    sy_log(SY_LOG_WARNING, "gltf", "scene.gltf", "meshes[%d]: %s", 3, "no indices");
    CHECK(s.calls == 1 && s.level == SY_LOG_WARNING);
    CHECK(!strcmp(s.module, "gltf") && !strcmp(s.item, "scene.gltf") && !s.item_null);
    CHECK_MSG(!strcmp(s.message, "meshes[3]: no indices"), "'%s'", s.message);
    sy_log(SY_LOG_ERROR, NULL, NULL, "plain");
    CHECK(s.calls == 2 && s.level == SY_LOG_ERROR && !strcmp(s.module, "sy") && s.item_null && !strcmp(s.message, "plain"));
    /* longer than the internal buffer: delivered whole */
    char big[3000];
    memset(big, 'x', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    sy_log(SY_LOG_NOTE, "raster", NULL, "%s!", big);
    CHECK(s.calls == 3 && strlen(s.message) == sizeof big && s.message[sizeof big - 1] == '!');
    sy_log_set_callback(NULL, NULL);
    return 0;
}

static int test_level_filter(void)
{
    seen s = {0};
    sy_log_set_callback(record, &s);
    sy_log_set_level(SY_LOG_WARNING);
    CHECK(sy_log_get_level() == SY_LOG_WARNING);
    sy_log(SY_LOG_NOTE, "x", NULL, "dropped");
    sy_log(SY_LOG_DEBUG, "x", NULL, "dropped");
    CHECK(s.calls == 0 && !sy_log_enabled(SY_LOG_NOTE) && sy_log_enabled(SY_LOG_WARNING));
    sy_log(SY_LOG_WARNING, "x", NULL, "kept");
    CHECK(s.calls == 1);
    sy_log_set_level(SY_LOG_ERROR); /* sy -q */
    sy_log(SY_LOG_WARNING, "x", NULL, "dropped");
    sy_log(SY_LOG_ERROR, "x", NULL, "kept");
    CHECK(s.calls == 2 && s.level == SY_LOG_ERROR);
    sy_log_set_level(SY_LOG_DEBUG); /* sy -v */
    sy_log(SY_LOG_DEBUG, "x", NULL, "kept");
    CHECK(s.calls == 3 && s.level == SY_LOG_DEBUG);
    sy_log_set_level((sy_log_level)99); /* clamped */
    CHECK(sy_log_get_level() == SY_LOG_DEBUG);
    sy_log_set_level(SY_LOG_NOTE);
    sy_log_set_callback(NULL, NULL);
    CHECK(!strcmp(sy_log_level_name(SY_LOG_WARNING), "warning") && !strcmp(sy_log_level_name(SY_LOG_NOTE), "note"));
    return 0;
}

/* Runs fn with stderr going to a temporary file; returns what was written (malloc()ed). */
static char *capture_stderr(void (*fn)(void))
{
    char path[] = "/tmp/sy_test_log_XXXXXX";
    int fd = mkstemp(path);
    if (fd < 0) return NULL;
    unlink(path);
    fflush(stderr);
    int saved = dup(2);
    dup2(fd, 2);
    fn();
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    off_t n = lseek(fd, 0, SEEK_END);
    char *buf = calloc(1, (size_t)n + 1);
    if (buf && pread(fd, buf, (size_t)n, 0) != n) buf[0] = '\0';
    close(fd);
    return buf;
}

static void log_defaults(void)
{
    sy_log(SY_LOG_WARNING, "gltf", "scene.gltf", "meshes[0]: %d vertices", 7);
    sy_log(SY_LOG_NOTE, "raster", NULL, "a note");
    sy_log(SY_LOG_DEBUG, "raster", NULL, "not shown at the default level");
    sy_log(SY_LOG_ERROR, "sy", "", "empty item");
}

static int test_default_stderr(void)
{
    sy_log_set_callback(NULL, NULL);
    sy_log_set_level(SY_LOG_NOTE);
    char *out = capture_stderr(log_defaults);
    CHECK(out);
    const char *want = "sy: warning: scene.gltf: meshes[0]: 7 vertices\nsy: note: a note\nsy: error: empty item\n";
    int ok = !strcmp(out, want);
    if (!ok) fprintf(stderr, "got:\n%s\nwanted:\n%s", out, want);
    free(out);
    CHECK(ok);
    return 0;
}

/* several threads: the callback's calls are serialised, so a plain counter stays exact */
static int g_count;
static void count(void *user, sy_log_level level, const char *module, const char *item, const char *message)
{
    (void)user, (void)level, (void)module, (void)item, (void)message;
    int c = g_count;
    if (c % 1000 == 0) sy_log(SY_LOG_DEBUG, "nested", NULL, "dropped at the default level"); /* no deadlock */
    g_count = c + 1;
}

static void *spam(void *arg)
{
    (void)arg;
    for (int i = 0; i < 5000; ++i) sy_log(SY_LOG_WARNING, "t", NULL, "%d", i);
    return NULL;
}

static int test_threads(void)
{
    g_count = 0;
    sy_log_set_level(SY_LOG_NOTE);
    sy_log_set_callback(count, NULL);
    pthread_t t[4];
    for (int i = 0; i < 4; ++i) CHECK(pthread_create(&t[i], NULL, spam, NULL) == 0);
    for (int i = 0; i < 4; ++i) pthread_join(t[i], NULL);
    sy_log_set_callback(NULL, NULL);
    CHECK_MSG(g_count == 20000, "%d calls", g_count);
    return 0;
}

SY_CHECK_MAIN("test_log", SY_TEST(test_callback_fields), SY_TEST(test_level_filter), SY_TEST(test_default_stderr),
              SY_TEST(test_threads))
