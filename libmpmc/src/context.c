/* The context: owns the last error and the log level; every create call takes one. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc_impl.h"

/* The API's enums travel to and from Fortran as integer(c_int) (fortran/mpmc.f90) */
#define MPMC_INT_SIZED(e) _Static_assert(sizeof(e) == sizeof(int), #e " is not int-sized")
MPMC_INT_SIZED(mpmc_error);
MPMC_INT_SIZED(mpmc_log_level);
MPMC_INT_SIZED(mpmc_basis);
MPMC_INT_SIZED(mpmc_wall_kind);
MPMC_INT_SIZED(mpmc_fbar_mode);
MPMC_INT_SIZED(mpmc_solver);
MPMC_INT_SIZED(mpmc_kernels);
MPMC_INT_SIZED(mpmc_field);
MPMC_INT_SIZED(mpmc_phase);
MPMC_INT_SIZED(mpmc_dp_match);

/**
 * @brief Create a context.
 * @param[out] ctx the new context
 */
int mpmc_context_create(mpmc_context *ctx) {
  if (!ctx) return MPMC_ERR_ARG;
  *ctx = calloc(1, sizeof **ctx);
  if (!*ctx) return MPMC_ERR_MEMORY;
  (*ctx)->log_level = MPMC_LOG_WARNING;
  return MPMC_SUCCESS;
}

/**
 * @brief Destroy a context; accepts NULL and sets the handle to NULL.
 */
int mpmc_context_destroy(mpmc_context *ctx) {
  if (!ctx) return MPMC_SUCCESS;
  free(*ctx);
  *ctx = NULL;
  return MPMC_SUCCESS;
}

/**
 * @brief The message of the last failure recorded in ctx ("" when none).
 */
const char *mpmc_context_last_error(const mpmc_context ctx) {
  if (!ctx) return "no context";
  return ctx->last_msg;
}

/**
 * @brief Copy the last error message into buf (for callers that own the buffer, e.g. Fortran).
 * @param buf destination, always NUL-terminated
 * @param len size of buf
 */
int mpmc_context_get_last_error(const mpmc_context ctx, char *buf, int len) {
  if (!ctx || !buf || len <= 0) return MPMC_ERR_ARG;
  snprintf(buf, (size_t)len, "%s", ctx->last_msg);
  return MPMC_SUCCESS;
}

/** @brief Forget the last error. */
int mpmc_context_clear_error(mpmc_context ctx) {
  if (!ctx) return MPMC_ERR_ARG;
  ctx->last_code = 0;
  ctx->last_msg[0] = '\0';
  return MPMC_SUCCESS;
}

/** @brief Set the log level (mpmc_log_level); messages go to stderr. */
int mpmc_context_set_log_level(mpmc_context ctx, mpmc_log_level level) {
  if (!ctx) return MPMC_ERR_ARG;
  MPMC_CHECK(level >= MPMC_LOG_SILENT && level <= MPMC_LOG_DEBUG, ctx, MPMC_ERR_ARG,
             "log level %d outside [0, 4]", level);
  ctx->log_level = level;
  return MPMC_SUCCESS;
}

/** @brief The library's version. */
int mpmc_version(int *major, int *minor, int *patch) {
  if (major) *major = MPMC_VERSION_MAJOR;
  if (minor) *minor = MPMC_VERSION_MINOR;
  if (patch) *patch = MPMC_VERSION_PATCH;
  return MPMC_SUCCESS;
}
