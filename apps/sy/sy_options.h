/* sy_options.h — getopt_long for every sy command, with long options matched exactly (issue 32).
 *
 * getopt_long takes any unambiguous beginning of a long option for the option ("--frame 10" is
 * read as "--frames 10"), so a mistyped or half-remembered option silently does something else.
 * sy_getopt refuses that: a long option must be spelled out in full (or as --name=value). An
 * abbreviation, and an ambiguous one, is a usage error naming the options it begins; sy_getopt
 * writes it to stderr and returns SY_GETOPT_ERROR, on which the command exits with status 2.
 * Everything else is getopt_long's behaviour (GNU ordering, "--" ends the options, ':' at the start
 * of shortopts for missing values).
 * Thread-safety: like getopt_long (process-wide optind / optarg; one parser at a time). */
#ifndef SY_OPTIONS_H
#define SY_OPTIONS_H

#include <getopt.h>

/* Returned after a usage error that sy_getopt has reported itself. */
#define SY_GETOPT_ERROR (-3)

/* getopt_long(argc, argv, shortopts, longopts, NULL) that refuses abbreviated long options; who
 * begins the message ("sy render"). */
int sy_getopt(int argc, char **argv, const char *shortopts, const struct option *longopts, const char *who);

#endif
