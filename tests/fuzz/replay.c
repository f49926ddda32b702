/* Replays the fuzzing corpus through the fuzz target (tests/fuzz/fuzz_scene.c) with an
 * ordinary compiler, as the CTest fuzz-scene-replay: every file (or every file of every
 * directory) named on the command line is fed to LLVMFuzzerTestOneInput once.  A crash, a
 * sanitizer report (ASan builds) or an abort from the target's property checks fails the
 * test; an empty corpus fails too (a replay of nothing cannot fail). */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int replay_file(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) {
    fprintf(stderr, "replay: cannot open %s\n", path);
    return -1;
  }
  size_t cap = 4096, len = 0;
  uint8_t *buf = malloc(cap);
  for (size_t got; buf && (got = fread(buf + len, 1, cap - len, f)) > 0;) {
    len += got;
    if (len == cap) {
      uint8_t *b = realloc(buf, cap *= 2);
      if (!b) free(buf);
      buf = b;
    }
  }
  fclose(f);
  if (!buf) return -1;
  LLVMFuzzerTestOneInput(buf, len);
  free(buf);
  return 0;
}

static int cmp(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

int main(int argc, char **argv) {
  long n = 0;
  for (int i = 1; i < argc; ++i) {
    struct stat st;
    if (stat(argv[i], &st)) {
      fprintf(stderr, "replay: %s does not exist\n", argv[i]);
      return 1;
    }
    if (!S_ISDIR(st.st_mode)) {
      if (replay_file(argv[i])) return 1;
      ++n;
      continue;
    }
    DIR *d = opendir(argv[i]);
    if (!d) return 1;
    char **names = NULL;
    size_t k = 0;
    for (struct dirent *e; (e = readdir(d));) {
      if (e->d_name[0] == '.') continue;
      char **nn = realloc(names, sizeof *names * (k + 1));
      if (!nn) return 1;
      names = nn;
      names[k] = malloc(strlen(argv[i]) + strlen(e->d_name) + 2);
      if (!names[k]) return 1;
      sprintf(names[k++], "%s/%s", argv[i], e->d_name);
    }
    closedir(d);
    if (k) qsort(names, k, sizeof *names, cmp); /* a fixed order: failures reproduce */
    for (size_t j = 0; j < k; ++j) {
      if (replay_file(names[j])) return 1;
      free(names[j]);
      ++n;
    }
    free(names);
  }
  if (n == 0) {
    fprintf(stderr, "replay: expected at least one corpus file, got none\n");
    return 1;
  }
  return 0;
}
