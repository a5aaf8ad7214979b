/* The radiosity run's log, errors and clock (runstate.h), shared by the run and its
 * photometric part. */
#include "runstate.h"

#include <stdarg.h>
#include <stdio.h>

/* The seconds left of budget counted from a->started. */
double ulam__run_time_left(const args *a, double budget)
{
    if (!(budget > 0)) return budget;
    double left = budget - (ulam_now() - a->started);
    return left > 1e-6 ? left : 1e-6;
}

/* A line to the caller's log. */
void ulam__run_log(const args *a, const char *fmt, ...)
{
    if (!a->log) return;
    va_list ap;
    va_start(ap, fmt);
    vfprintf(a->log, fmt, ap);
    va_end(ap);
}

/* A located error line to the caller's log; its status. */
int ulam__run_error(const args *a, const char *file, const ulam_error *err)
{
    if (err->file[0]) file = err->file;
    if (file && err->line > 0) ulam__run_log(a, "ulam: %s:%ld: ", file, err->line);
    else if (file) ulam__run_log(a, "ulam: %s: ", file);
    else ulam__run_log(a, "ulam: ");
    ulam__run_log(a, "error: %s%s%s\n", ulam_strerror(err->status), err->msg[0] ? ": expected " : "", err->msg);
    return err->status;
}
