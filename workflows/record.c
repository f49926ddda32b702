/* The workflow's record in a checkpoint: where the run stands (scene, stage, the stage's
 * clock, overrides, walls, finished stages), written as text into the checkpoint's metadata
 * (the checkpoint's checksum covers it) and read back, field by field, by `mpmc resume`.
 * Format: "mpmc-workflow 1", then one "key value" line per scalar field and one line per
 * override ("set k=v"), wall ("wall id") and finished stage ("done t steps wall reason F");
 * doubles with 17 digits, so that a resumed run takes the same steps. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "wf.h"

#define HEADER "mpmc-workflow 1\n"

/* the scalar fields: key, and where the value goes in a record */
typedef struct {
  const char *key;
  size_t off;
  char type; /* 'd' double, 'i' int, 'l' long */
} field;
#define F(key, member, type) {key, offsetof(wf_record, member), type}
static const field fields[] = {
    F("stage", stage, 'i'),           F("setup", setup, 'i'),
    F("stage_time", clock.t_stage, 'd'), F("stage_steps", steps, 'l'),
    F("ke_max", clock.ke_max, 'd'),   F("ke_below", ke_below, 'd'),
    F("strength", strength, 'd'),     F("dt", clock.dt, 'd'),
    F("ke", clock.ke, 'd'),           F("ratio", clock.ratio, 'd'),
    F("next_series", clock.next_series, 'd'), F("next_snap", clock.next_snap, 'd'),
};
#undef F
#define NFIELD (sizeof fields / sizeof fields[0])

static const char *const reasons[] = {"time", "quasi_static", "max_time", "fos", NULL};

/**
 * @brief The record as text into buf (len bytes); 0, or -1 when it does not fit.
 */
int wf_record_format(const wf_record *r, char *buf, size_t len) {
  size_t l = (size_t)snprintf(buf, len, HEADER "scene %s\n", r->scene);
  for (size_t k = 0; k < NFIELD && l < len; ++k) {
    const char *at = (const char *)r + fields[k].off;
    if (fields[k].type == 'd')
      l += (size_t)snprintf(buf + l, len - l, "%s %.17g\n", fields[k].key, *(const double *)at);
    else if (fields[k].type == 'i')
      l += (size_t)snprintf(buf + l, len - l, "%s %d\n", fields[k].key, *(const int *)at);
    else
      l += (size_t)snprintf(buf + l, len - l, "%s %ld\n", fields[k].key, *(const long *)at);
  }
  for (int i = 0; i < r->nset && l < len; ++i) l += (size_t)snprintf(buf + l, len - l, "set %s\n", r->sets[i]);
  for (int i = 0; i < r->nwall && l < len; ++i) l += (size_t)snprintf(buf + l, len - l, "wall %d\n", r->walls[i]);
  for (int i = 0; i < r->ndone && l < len; ++i) {
    const wf_stage_record *d = &r->done[i];
    l += (size_t)snprintf(buf + l, len - l, "done %.17g %ld %.17g %s %.17g\n", d->sim_time, d->steps,
                          d->wall_seconds, d->reason ? d->reason : "max_time", d->strength);
  }
  return l < len ? 0 : -1;
}

/** @brief Append one --set override (copied) to the record; 0 or MPMC_ERR_MEMORY. */
int wf_record_add_set(wf_record *r, const char *set) {
  char **s2 = realloc(r->sets, sizeof *s2 * (size_t)(r->nset + 1));
  if (!s2) return MPMC_ERR_MEMORY;
  r->sets = s2;
  if (!(s2[r->nset] = strdup(set))) return MPMC_ERR_MEMORY;
  r->nset++;
  return 0;
}

/* one line (without its newline) into r: 0, or the error */
static int parse_line(char *line, wf_record *r, int *seen) {
  char *sp = strchr(line, ' ');
  if (!sp) return MPMC_ERR_FORMAT;
  *sp = '\0';
  const char *key = line, *val = sp + 1;
  char *end = NULL;
  if (!strcmp(key, "scene")) {
    return snprintf(r->scene, sizeof r->scene, "%s", val) < (int)sizeof r->scene ? 0 : MPMC_ERR_FORMAT;
  } else if (!strcmp(key, "set")) {
    return wf_record_add_set(r, val);
  } else if (!strcmp(key, "wall")) {
    int *w2 = realloc(r->walls, sizeof *w2 * (size_t)(r->nwall + 1));
    if (!w2) return MPMC_ERR_MEMORY;
    r->walls = w2;
    w2[r->nwall] = (int)strtol(val, &end, 10);
    if (end == val || *end) return MPMC_ERR_FORMAT;
    r->nwall++;
    return 0;
  } else if (!strcmp(key, "done")) {
    wf_stage_record *d2 = realloc(r->done, sizeof *d2 * (size_t)(r->ndone + 1));
    if (!d2) return MPMC_ERR_MEMORY;
    r->done = d2;
    wf_stage_record *d = &d2[r->ndone];
    memset(d, 0, sizeof *d);
    char reason[32];
    if (sscanf(val, "%lf %ld %lf %31s %lf", &d->sim_time, &d->steps, &d->wall_seconds, reason, &d->strength) != 5)
      return MPMC_ERR_FORMAT;
    for (int k = 0; reasons[k] && !d->reason; ++k)
      if (!strcmp(reason, reasons[k])) d->reason = reasons[k];
    if (!d->reason) return MPMC_ERR_FORMAT;
    r->ndone++;
    return 0;
  }
  for (size_t k = 0; k < NFIELD; ++k) {
    if (strcmp(key, fields[k].key)) continue;
    char *at = (char *)r + fields[k].off;
    if (fields[k].type == 'd')
      *(double *)at = strtod(val, &end);
    else if (fields[k].type == 'i')
      *(int *)at = (int)strtol(val, &end, 10);
    else
      *(long *)at = strtol(val, &end, 10);
    if (end == val || *end) return MPMC_ERR_FORMAT;
    *seen |= 1 << k;
    return 0;
  }
  return MPMC_ERR_FORMAT; /* a key this version does not know */
}

/**
 * @brief The record from a checkpoint's metadata (NULL: none) into r (freed by the caller
 *        with wf_record_free).  0, MPMC_ERR_FORMAT (msg names the line) or MPMC_ERR_MEMORY.
 */
int wf_record_parse(const char *text, wf_record *r, char *msg, size_t len) {
  memset(r, 0, sizeof *r);
  r->stage = -1;
  r->strength = 1.0;
  r->ke_below = -1.0;
  r->clock.ratio = 1.0;
  if (!text || strncmp(text, HEADER, strlen(HEADER)) != 0) {
    snprintf(msg, len, "no workflow record (\"mpmc-workflow 1\")");
    return MPMC_ERR_FORMAT;
  }
  char *copy = strdup(text + strlen(HEADER));
  if (!copy) return MPMC_ERR_MEMORY;
  int e = 0, seen = 0, n = 1;
  for (char *save = NULL, *line = strtok_r(copy, "\n", &save); line && !e; line = strtok_r(NULL, "\n", &save)) {
    ++n;
    char shown[96];
    snprintf(shown, sizeof shown, "%s", line);
    e = parse_line(line, r, &seen);
    if (e == MPMC_ERR_FORMAT) snprintf(msg, len, "record line %d: '%s'", n, shown);
  }
  free(copy);
  if (!e && (!r->scene[0] || !(seen & 1) || r->stage < 0)) {
    snprintf(msg, len, "the record names no scene or stage");
    e = MPMC_ERR_FORMAT;
  }
  return e;
}

/** @brief Free what a record owns (its overrides, walls and finished stages). */
void wf_record_free(wf_record *r) {
  for (int i = 0; i < r->nset; ++i) free(r->sets[i]);
  free(r->sets);
  free(r->walls);
  free(r->done);
  memset(r, 0, sizeof *r);
}
