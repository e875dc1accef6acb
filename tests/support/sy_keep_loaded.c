/* sy_keep_loaded.c — linked into every executable of the sanitizer build (SY_SANITIZE=ON) only.
 *
 * LeakSanitizer checks for leaks at process exit and symbolizes the allocation stacks then. A GL
 * driver (Mesa's DRI driver, libGLX_mesa, ...) is dlopen()ed by the GL loader and dlclose()d again
 * when the window or context goes away, so the driver's own process-lifetime allocations lose the
 * module that holds the last pointer to them and are reported as leaks "in <unknown module>".
 * This definition of dlclose() takes precedence over libc's (and ASan's interceptor) for the whole
 * process, because the executable comes first in the symbol lookup order and exports it
 * (-Wl,--export-dynamic-symbol=dlclose): every dlopen()ed module stays mapped until exit, its
 * globals stay reachable roots, and its allocations are not leaks. Nothing is suppressed, so a leak
 * of ours is still reported, with a full stack. Never used in a normal build.
 *
 * It also sets the sanitizer build's default ASan options (__asan_default_options; ASAN_OPTIONS
 * adds to them): intercept_tls_get_addr=0. Up to GCC 13 / LLVM 16 the runtime's __tls_get_addr
 * interceptor takes a dynamic TLS block whose start lies 16 bytes into a page for the header of
 * glibc before 2.25 and reads the two words before it as the block's address and size; since
 * glibc 2.25 there is no such header, a block of a dlopen()ed module (Mesa's drivers) lands there
 * by chance, and LeakSanitizer's stop-the-world tracer crashes at exit ("Tracer caught signal 11
 * ... LeakSanitizer has encountered a fatal error", exit 134) before any leak check: a rare flake
 * of the ASan configuration (seen in integration_cli's raster render with --env and in
 * integration_view_cluster). The leak check itself runs as before. */
int dlclose(void *handle);
const char *__asan_default_options(void);

const char *__asan_default_options(void)
{
    return "intercept_tls_get_addr=0";
}

int dlclose(void *handle)
{
    (void)handle;
    return 0;
}
