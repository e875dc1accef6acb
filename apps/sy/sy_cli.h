/* sy_cli.h — what every sy command shares on its command line (sy_cli.c).
 *
 * Every command, and sy itself before the command, declares its options in a table of sy_cli_opt
 * (name, kind, where the value goes, its range) and reads them with sy_cli_parse, which builds the
 * getopt_long table from it and parses with getopt_long (GNU ordering: options and operands in any
 * order, "--" ends the options, --name=value) through sy_getopt, which refuses abbreviated long
 * options (sy_options.h: "--frame" is no "--frames"). The options every command takes (the world and
 * loader flags, -q / -v, --help) are applied on the way; a declared option's value is stored where
 * its entry says (a bad value is a usage error naming the option and, for a number, its range), and
 * only the options whose meaning is the command's own (SY_CLI_CODE) come back to it. A command that
 * takes none of the common options (sy serve, the benchmarks with their own usage text) gives its own
 * usage text (sy_cli_parser.usage): then only -q, -v and --help are taken besides its own. Numbers are
 * read by one parser each: sy_cli_parse_uint (whole numbers), sy_cli_parse_double (one number),
 * sy_cli_parse_floats (a list X,Y,...).
 * Exit status: 0 success, 1 failure (sy_cli_fail), 2 usage error (the bad option or value is
 * named), 130 interrupted. Thread-safety: the main thread only (getopt's globals). */
#ifndef SY_CLI_H
#define SY_CLI_H

#include "sy_common.h"

#include <getopt.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

enum {
    OPT_STOP = -2, /* sy_cli_parse: the command ends with *status (after --help or a usage error) */
    OPT_HELP = 0x100, OPT_VERSION, OPT_ENV, OPT_ENV_COLOR, OPT_ENV_INTENSITY, OPT_ENV_HIDDEN, OPT_BACKGROUND,
    OPT_NO_DEFAULT_LIGHT, OPT_ALLOW_PATH, OPT_STRICT, OPT_MAX_SCENE_MB, OPT_VARIANT,
    /* the commands' own long options (cluster ones: SY_CLUSTER_OPT_*, sy_cluster_cli.h) */
    OPT_SPP, OPT_TIME, OPT_AOV, OPT_CAMERA, OPT_PARAMS, OPT_GL, OPT_FILTER, OPT_THRESHOLD, OPT_HALF, OPT_EXPOSURE,
    OPT_TONEMAP, OPT_STEREO, OPT_EYE_SEP, OPT_ZERO_PARALLAX, OPT_OVERLAY, OPT_COMPOSITE, OPT_FRAMES, OPT_BACKENDS,
    OPT_SCREENSHOT, OPT_KEYS, OPT_TOP, OPT_REPEATS, OPT_REFERENCE, OPT_NODES, OPT_TRIS, OPT_JSON, OPT_GLB, OPT_MAX_MEMORY,
    OPT_BUDGET, OPT_AT, OPT_CLIP, OPT_LOOK_AT, OPT_FOV, OPT_ORBIT, OPT_REPEAT, OPT_FPS, OPT_RESUME, OPT_HIDE,
    OPT_ISOLATE, OPT_SELECT, OPT_TEMPORAL, OPT_NO_TEMPORAL, OPT_SHUTTER, OPT_MOTION_BLUR, OPT_SHUTTER_SAMPLES,
    OPT_CLIP_CAP, OPT_BOOKMARK, OPT_BOOKMARKS, OPT_MEASURE, OPT_PLANE, OPT_SUB_FRAMES, OPT_SHUTTER_STEPS, OPT_SEED,
    OPT_OWN_HELP, /* --help of a command with its own usage text (sy_cli_parser.usage) */
    OPT_OWN_FIRST /* a command may number codes of its own from here (below the cluster's, 0x200) */
};
/* How a declared option is read. */
typedef enum sy_cli_kind {
    SY_CLI_CODE, /* its code comes back from sy_cli_parse (the command reads optarg, when it has one) */
    SY_CLI_TEXT, /* const char *: the value as given */
    SY_CLI_FLAG, /* bool: true (no value); to NULL: accepted and without effect */
    SY_CLI_UINT, /* uint32_t: a whole number in lo..hi (sy_cli_parse_uint) */
    SY_CLI_COUNT, /* uint64_t: a whole number in lo..hi, k (thousand) or M (million) after it allowed: 10M */
    SY_CLI_REAL, /* double: a finite number in lo..hi (sy_cli_parse_double) */
    SY_CLI_FLOAT, /* float: a number in lo..hi (sy_cli_parse_double); lo > hi: any, NaN and infinities
                     too (what reads it says why not) */
} sy_cli_kind;

/* One option of a command, declared: its names, how it is read and where its value goes. */
typedef struct sy_cli_opt {
    const char *name; /* the long name without "--"; NULL: a short option only */
    int code;         /* the short option's letter, or the long option's code (OPT_*) */
    sy_cli_kind kind;
    bool value;       /* it takes a value (every kind but FLAG, and CODE as declared) */
    void *to;         /* where the value goes (the kind's type); NULL for CODE */
    double lo, hi;    /* UINT, REAL, FLOAT: the accepted range */
} sy_cli_opt;

#define SY_CLI_OPT_CODE(name, code, has_value) {(name), (code), SY_CLI_CODE, (has_value), NULL, 0, 0}
#define SY_CLI_OPT_TEXT(name, code, to) {(name), (code), SY_CLI_TEXT, true, (const char **){(to)}, 0, 0}
#define SY_CLI_OPT_FLAG(name, code, to) {(name), (code), SY_CLI_FLAG, false, (bool *){(to)}, 0, 0}
#define SY_CLI_OPT_UINT(name, code, to, lo, hi) {(name), (code), SY_CLI_UINT, true, (uint32_t *){(to)}, (lo), (hi)}
#define SY_CLI_OPT_COUNT(name, code, to, lo, hi) {(name), (code), SY_CLI_COUNT, true, (uint64_t *){(to)}, (lo), (hi)}
#define SY_CLI_OPT_REAL(name, code, to, lo, hi) {(name), (code), SY_CLI_REAL, true, (double *){(to)}, (lo), (hi)}
#define SY_CLI_OPT_FLOAT(name, code, to, lo, hi) {(name), (code), SY_CLI_FLOAT, true, (float *){(to)}, (lo), (hi)}
#define SY_CLI_OPT_FLOAT_ANY(name, code, to) {(name), (code), SY_CLI_FLOAT, true, (float *){(to)}, 1, 0}

/* A command's arguments being read: the fields up to `view` are the command's to set, the first five
 * with SY_CLI_ARGS, the rest by name; the remaining fields are sy_cli_parse's:
 *   sy_cli_parser p = {SY_CLI_ARGS("compare", argc, argv, opts), .w = &w, .h = &h, .min_size = 1}; */
typedef struct sy_cli_parser {
    const char *cmd;          /* the command as `sy help` names it ("render", "bench sync"); NULL: sy's own
                                 options before the command (they end at the first operand, the command) */
    int argc;
    char **argv;              /* argv[0]: the command's name */
    const sy_cli_opt *opts;   /* the command's own options */
    size_t count;             /* how many */
    uint32_t *w, *h;          /* non-NULL: -w W and -h H, pixels from min_size to 16384 */
    uint32_t min_size;
    bool cluster;             /* the cluster options too (SY_CLUSTER_CLI_OPTIONS), whose codes come back
                                 (for sy_cluster_cli_getopt) */
    bool view;                /* the camera placement options too (VIEW_OPTIONS) */
    const char *usage;        /* non-NULL: the command takes none of the common options but -q, -v and
                                 --help, which prints this text (its own usage) on stdout */
    int status;               /* after OPT_STOP: the command's exit status */
    /* sy_cli_parse's own */
    bool started;
    struct option lo[96];     /* the getopt_long table (for sy_cli_option_name) */
    char shortopts[48];
} sy_cli_parser;

/* The next option of p's arguments for the command to handle: the code of a SY_CLI_CODE option or
 * of a cluster option, -1 after the last option (the operands are argv[optind..argc-1]), or OPT_STOP
 * with p->status (0 after --help, 2 after a usage error, named on stderr). Every other option is
 * applied on the way. A command without SY_CLI_CODE options calls it once:
 * `if (sy_cli_parse(&p) != -1) return p.status;`. */
int sy_cli_parse(sy_cli_parser *p);
/* The first fields of a sy_cli_parser: the command, its arguments and its option table (an array). */
#define SY_CLI_ARGS(cmd_, argc_, argv_, opts_)                                                             \
    .cmd = (cmd_), .argc = (argc_), .argv = (argv_), .opts = (opts_), .count = sizeof(opts_) / sizeof((opts_)[0])

/* The one SCENE operand a command takes after its options (argv[optind]) into *scene; returns 0, or 2
 * after a usage error (none or more than one, with cmd's usage on stderr). */
int sy_cli_scene_operand(const char *cmd, int argc, char **argv, const char **scene);

/* The command summary (cmd NULL) or the entries of one command ("render", "bench", "bench sync") and
 * the common part, to f: stdout for --help (exit 0), stderr after a usage error (exit 2). */
void sy_cli_usage_to(FILE *f, const char *cmd);
/* A usage error without a named option (an operand missing): what (may be NULL) and the command's
 * usage on stderr; returns 2. */
int sy_cli_usage_of(const char *cmd, const char *what);
/* "--name" of a long option's code in a getopt_long table (for messages; a static buffer). */
const char *sy_cli_option_name(const struct option *lo, int c);
/* A usage error naming the option and the value it did not accept; returns 2. */
int sy_cli_bad_value(const char *opt, const char *value);
/* s as a whole decimal number in lo..hi: digits only (no sign, no space), nothing after them. The one
 * integer parser of the options (and of the numbers in their values). */
bool sy_cli_parse_uint(const char *s, uint64_t lo, uint64_t hi, uint64_t *out);
/* s as a finite number in lo..hi (nothing after it); lo > hi: any number strtod reads whole, NaN and
 * infinities too. The one parser of an option that is a number. */
bool sy_cli_parse_double(const char *s, double lo, double hi, double *out);
/* The first len characters of text as a list of min_n..max_n finite numbers X,Y,... into out
 * (*n_out: how many): each begins right after the comma (no space), none is empty, nothing after the
 * last. The one parser of an option value that is a list of numbers. */
bool sy_cli_parse_floats(const char *text, size_t len, int min_n, int max_n, float *out, int *n_out);
/* --clip A,B,C,D of command cmd: appends the section plane (four finite numbers, a non-zero normal)
 * to planes (room for SY_CLIP_PLANES_MAX) and returns 0; a bad value or a seventh plane: a usage
 * error naming --clip on stderr, returns 2. */
int sy_cli_add_clip_plane(const char *value, float (*planes)[4], uint32_t *count);
/* A plane A,B,C,D of option opt (four finite numbers, a non-zero normal) into q and returns 0; else
 * a usage error naming opt on stderr, returns 2. */
int sy_cli_parse_plane(const char *opt, const char *value, float q[4]);
/* true when an --clip value is a section plane (it has a comma) rather than an animation clip's
 * name or index (sy render --clip NAME|INDEX). */
bool sy_cli_is_clip_plane(const char *value);
/* --clip-cap RRGGBB (or #RRGGBB): the section cap colour, six hex digits of sRGB, into rgb as
 * linear RGB and returns 0; anything else: a usage error naming --clip-cap on stderr, returns 2. */
int sy_cli_parse_cap_color(const char *value, float rgb[3]);

/* The error on the log (stderr); returns 1, the exit status of a failure. */
int sy_cli_fail(const sy_error *e);
/* The back-end a command uses without -b: the registry's default (sy_mediator_default); NULL with
 * *err when there is none. */
const char *sy_cli_default_backend(sy_error *err);
/* s ends in suffix, ignoring case. */
bool sy_cli_ends_with(const char *s, const char *suffix);

#endif /* SY_CLI_H */
