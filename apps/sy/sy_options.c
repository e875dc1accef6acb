/* sy_options.c — getopt_long with long options matched exactly (see sy_options.h). */
#include "sy_options.h"

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

/* Writes the usage error for "--spelled" (an abbreviation, or no option at all when nothing
 * begins with it); false when no long option begins with it (then getopt's own error stands). */
static bool report_prefix(const char *arg, const struct option *lo, const char *who)
{
    const char *name = arg + 2;
    size_t n = strcspn(name, "=");
    int matches = 0;
    for (const struct option *o = lo; o->name; ++o)
        if (strlen(o->name) > n && !strncmp(o->name, name, n)) matches++;
    if (!matches) return false;
    fprintf(stderr, "%s: error: unknown option '--%.*s': long options are not abbreviated; %s: ", who, (int)n, name,
            matches == 1 ? "the option that begins so is" : "the options that begin so are");
    int k = 0;
    for (const struct option *o = lo; o->name; ++o)
        if (strlen(o->name) > n && !strncmp(o->name, name, n)) fprintf(stderr, "%s--%s", k++ ? ", " : "", o->name);
    bool has_at = false; /* --frame in sy render: a sequence (--frames) or one time (--at)? */
    for (const struct option *o = lo; o->name; ++o) has_at = has_at || !strcmp(o->name, "at");
    if (has_at && n == 5 && !strncmp(name, "frame", 5)) fprintf(stderr, "; one time on the scene clock: --at SECONDS");
    fprintf(stderr, " (%s --help lists the options)\n", who);
    return true;
}

int sy_getopt(int argc, char **argv, const char *shortopts, const struct option *longopts, const char *who)
{
    int idx = -1;
    int c = getopt_long(argc, argv, shortopts, longopts, &idx);
    if (c == '?' && optopt == 0 && optind > 0 && optind <= argc) { /* an unknown or ambiguous long option */
        const char *arg = argv[optind - 1];
        if (!strncmp(arg, "--", 2) && report_prefix(arg, longopts, who)) return SY_GETOPT_ERROR;
        return c;
    }
    if (idx < 0 || c == -1) return c; /* a short option, or the end */
    /* the element that named the long option: the last one taken, or the one before it when the
     * value came as the next element ("--name VALUE") */
    int at = optind - 1;
    if (optarg && at > 0 && optarg == argv[at]) at--;
    if (at < 0 || at >= argc || strncmp(argv[at], "--", 2) != 0) return c;
    const char *name = argv[at] + 2;
    size_t n = strcspn(name, "=");
    if (strlen(longopts[idx].name) == n && !strncmp(longopts[idx].name, name, n)) return c; /* spelled out */
    report_prefix(argv[at], longopts, who);
    return SY_GETOPT_ERROR;
}
