/* sy_testpoint.h — announced phases and test-only pause points of the sy tool (issue 32), so that a
 * test that interrupts or races sy waits for an event instead of sleeping.
 *
 * Two environment variables, both read once by sy_testpoint_start; without them every call here
 * does nothing:
 *   SY_TEST_PHASES=FILE   each phase sy reaches is appended to FILE as one line (its name), so a
 *                         test polls FILE for the line it waits for;
 *   SY_TEST_PAUSE=PHASE   on reaching PHASE (after announcing it) the thread that reached it stops
 *                         there until a signal ends the process (apps/sy/sy_signals.h), so a test's
 *                         interrupt lands in that phase and nowhere else. A hang guard lets it go
 *                         on after SY_TEST_PAUSE_SECONDS (default 120), with a message on stderr.
 * The phases:
 *   pass     sy render, progressive back-end: a pass has finished (the graceful first interrupt is
 *            armed; announced after every pass);
 *   tiles    sy render: the back-end reported its first finished tile of a frame (a render is in
 *            progress; no output file exists yet);
 *   frame    sy view: a settled frame was shown (announced after every one);
 *   commit   any output file: the temporary file is written and about to be renamed over the
 *            target (sy_atomic_file_set_commit_hook, formats/sy_file.h).
 * Thread-safety: sy_testpoint may be called from any thread; the state is set once at start. */
#ifndef SY_TESTPOINT_H
#define SY_TESTPOINT_H

/* Call once in main before any thread is started: reads the environment, installs the commit hook
 * when SY_TEST_PAUSE=commit or SY_TEST_PHASES is set. */
void sy_testpoint_start(void);

/* Announces phase (SY_TEST_PHASES) and stops there when it is SY_TEST_PAUSE. */
void sy_testpoint(const char *phase);

#endif
