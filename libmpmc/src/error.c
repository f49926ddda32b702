/* Error codes (X-macro in mpmc.h) and the last-error record of a context. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "mpmc_impl.h"

#define MPMC_ERROR_STRING_(name, msg) msg,
static const char *const error_strings[] = {MPMC_ERROR_LIST(MPMC_ERROR_STRING_)};
#undef MPMC_ERROR_STRING_

/**
 * @brief The message of an error code.
 * @param code an mpmc_error value
 * @return a static string; "unknown error code" for values outside the list
 */
const char *mpmc_error_string(int code) {
  if (code < 0 || code >= MPMC_ERROR_COUNT) return "unknown error code";
  return error_strings[code];
}

static const char *basename_of(const char *path) {
  const char *s = strrchr(path, '/');
  return s ? s + 1 : path;
}

/* The one place a context's last error is recorded: "message: body [file:line]". */
static int record(mpmc_context ctx, int code, const char *file, int line, const char *body) {
  ctx->last_code = code;
  snprintf(ctx->last_msg, sizeof ctx->last_msg, "%s: %s [%s:%d]", mpmc_error_string(code), body,
           basename_of(file), line);
  if (ctx->log_level >= MPMC_LOG_DEBUG) fprintf(stderr, "mpmc error: %s\n", ctx->last_msg);
  return code;
}

int mpmc_error_set(mpmc_context ctx, int code, const char *file, int line, const char *fmt, ...) {
  if (!ctx) return code;
  char body[MPMC_MSG_LEN - 256];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(body, sizeof body, fmt, ap);
  va_end(ap);
  return record(ctx, code, file, line, body);
}

/**
 * @brief Record an error in the context, as the library does for its own failures: for the
 *        libraries and callbacks built on libmpmc (the workflow, a user material).
 * @param ctx the context
 * @param code an mpmc_error value, recorded as the context's last code
 * @param file source file named in the message (its base name), may be NULL
 * @param line source line named in the message
 * @param message what went wrong, cut at the message buffer's size
 * @return code; MPMC_ERR_ARG when ctx or message is NULL
 */
int mpmc_context_set_error(mpmc_context ctx, int code, const char *file, int line,
                           const char *message) {
  if (!ctx || !message) return MPMC_ERR_ARG;
  char body[MPMC_MSG_LEN - 256];
  snprintf(body, sizeof body, "%s", message);
  return record(ctx, code, file ? file : "?", line, body);
}

/**
 * @brief The code of the context's last recorded error (MPMC_SUCCESS after
 *        mpmc_context_clear_error).
 * @param ctx the context
 * @param[out] code the code
 * @return MPMC_SUCCESS; MPMC_ERR_ARG when ctx or code is NULL
 */
int mpmc_context_get_last_code(const mpmc_context ctx, int *code) {
  if (!ctx || !code) return MPMC_ERR_ARG;
  *code = ctx->last_code;
  return MPMC_SUCCESS;
}

void mpmc_log(mpmc_context ctx, int level, const char *fmt, ...) {
  if (!ctx || level > ctx->log_level) return;
  va_list ap;
  va_start(ap, fmt);
  fputs(level <= MPMC_LOG_ERROR ? "mpmc error: " : level == MPMC_LOG_WARNING ? "mpmc warning: " : "mpmc: ",
        stderr);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
}
