/*
 * error.c: status strings, the version, messages.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <stdarg.h>
#include <stdio.h>

#include "internal.h"

const char *rbs_status_string(int status)
{
    switch (status) {
    case RBS_OK: return "success (a hit: rebounded)";
    case RBS_TRAPPED: return "trapped: still colliding after n_max collisions, or drawn trapped from the table";
    case RBS_FAILED: return "failed: a collision solve or a contact search of the direct model failed";
    case RBS_INVALID: return "invalid argument (a NULL pointer, a record too small, an unknown name or method, "
                             "bad weights, a hit's input out of range)";
    case RBS_ERR_IO: return "the file does not exist or cannot be opened";
    case RBS_ERR_FORMAT: return "not a readable rebound table (not HDF5, truncated, corrupt, another file type, "
                                "missing or malformed data)";
    case RBS_ERR_VERSION: return "a rebound table of another major format version";
    case RBS_ERR_MEMORY: return "out of memory";
    default: return "unknown status";
    }
}

#define RBS_STR2(x) #x
#define RBS_STR(x) RBS_STR2(x)

const char *rbs_version(void)
{
    return RBS_STR(RBS_VERSION_MAJOR) "." RBS_STR(RBS_VERSION_MINOR) "." RBS_STR(RBS_VERSION_PATCH);
}

int rbs_version_number(void)
{
    return RBS_VERSION_NUMBER;
}

void rbs_message(char *message, size_t message_size, const char *format, ...)
{
    if (!message || message_size == 0) return;
    va_list args;
    va_start(args, format);
    vsnprintf(message, message_size, format, args);
    va_end(args);
}
