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
 * of ours is still reported, with a full stack. Never used in a normal build. */
int dlclose(void *handle);

int dlclose(void *handle)
{
    (void)handle;
    return 0;
}
