/*
 * error.c: error strings, the version, messages.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <stdarg.h>
#include <stdio.h>

#include "internal.h"

const char *rbs_error_string(int code)
{
    switch (code) {
    case RBS_OK: return "success";
    case RBS_ERR_IO: return "the file does not exist or cannot be opened";
    case RBS_ERR_FORMAT: return "not a readable rebound table (not HDF5, truncated, corrupt, another file type, "
                                "missing or malformed data)";
    case RBS_ERR_VERSION: return "a rebound table of another major format version";
    case RBS_ERR_ARGUMENT: return "invalid argument";
    case RBS_ERR_MEMORY: return "out of memory";
    default: return "unknown error code";
    }
}

#define RBS_STR2(x) #x
#define RBS_STR(x) RBS_STR2(x)

const char *rbs_version(void)
{
    return RBS_STR(RBS_VERSION_MAJOR) "." RBS_STR(RBS_VERSION_MINOR) "." RBS_STR(RBS_VERSION_PATCH);
}

void rbs_message(char *message, size_t message_size, const char *format, ...)
{
    if (!message || message_size == 0) return;
    va_list args;
    va_start(args, format);
    vsnprintf(message, message_size, format, args);
    va_end(args);
}
