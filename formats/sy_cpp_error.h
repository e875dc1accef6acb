// sy_cpp_error.h — the exception being handled as a sy_result with its message, for the C++ parts
// of formats (the glTF shim, its GLB writer, the Draco decoder): every entry point of theirs ends in
// `catch (...) { return sy_error_from_exception(...); }`, so nothing C++ leaks through the C
// interface and every one classifies the same way. C++ only, header-only.
// Thread-safety: none needed (err is the caller's).
#ifndef SY_CPP_ERROR_H
#define SY_CPP_ERROR_H

#include "sy_common.h"

#include <exception>
#include <new>

// Call only inside a catch block. Sets err from the exception being handled and returns its code:
// std::bad_alloc: SY_ERR_OUT_OF_MEMORY, message `oom`; another std::exception: `code`, message
// what_prefix followed by what(); anything else: `code`, message `unknown`.
inline sy_result sy_error_from_exception(sy_error *err, sy_result code, const char *oom, const char *what_prefix,
                                         const char *unknown)
{
    try {
        throw;
    } catch (const std::bad_alloc &) {
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s", oom);
    } catch (const std::exception &e) {
        return sy_error_set(err, code, "%s%s", what_prefix, e.what());
    } catch (...) {
        return sy_error_set(err, code, "%s", unknown);
    }
}

#endif // SY_CPP_ERROR_H
