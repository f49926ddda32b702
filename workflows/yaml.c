/* Scene files' YAML layer: libyaml's event parser -> a tree (wf_node) that keeps
 * file:line:column for every key and value, and `--set key.path=value` overrides applied to
 * that tree.  The scene schema (scene.c) reads the tree. */
#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "wf.h"

/* ---- the tree --------------------------------------------------------------------- */
void wf_node_free(wf_node *n) {
  if (!n) return;
  for (int i = 0; i < n->n; ++i) {
    wf_node_free(n->items[i]);
    if (n->keys) free(n->keys[i]);
  }
  free(n->items);
  free(n->keys);
  free(n->key_line);
  free(n->key_col);
  free(n->value);
  free(n);
}

static wf_node *node_new(wf_kind kind, int line, int col, const char *origin) {
  wf_node *n = calloc(1, sizeof *n);
  if (!n) return NULL;
  n->kind = kind;
  n->line = line;
  n->col = col;
  n->origin = origin;
  return n;
}

static int node_push(wf_node *parent, const char *key, int kline, int kcol, wf_node *child) {
  if (parent->n == parent->cap) {
    const int cap = parent->cap ? 2 * parent->cap : 8;
    wf_node **it = realloc(parent->items, sizeof *it * (size_t)cap);
    if (!it) return -1;
    parent->items = it;
    if (parent->kind == WF_MAP) {
      char **k = realloc(parent->keys, sizeof *k * (size_t)cap);
      if (!k) return -1;
      parent->keys = k;
      int *kl = realloc(parent->key_line, sizeof *kl * (size_t)cap);
      if (!kl) return -1;
      parent->key_line = kl;
      int *kc = realloc(parent->key_col, sizeof *kc * (size_t)cap);
      if (!kc) return -1;
      parent->key_col = kc;
    }
    parent->cap = cap;
  }
  if (parent->kind == WF_MAP) {
    parent->keys[parent->n] = strdup(key);
    if (!parent->keys[parent->n]) return -1;
    parent->key_line[parent->n] = kline;
    parent->key_col[parent->n] = kcol;
  }
  parent->items[parent->n++] = child;
  return 0;
}

static int map_index(const wf_node *m, const char *key) {
  if (!m || m->kind != WF_MAP) return -1;
  for (int i = 0; i < m->n; ++i)
    if (strcmp(m->keys[i], key) == 0) return i;
  return -1;
}

const wf_node *wf_map_get(const wf_node *m, const char *key) {
  const int i = map_index(m, key);
  return i < 0 ? NULL : m->items[i];
}

/* ---- parsing: events -> tree --------------------------------------------------------- */
#define WF_DEPTH 64
typedef struct {
  wf_node *node;
  char *pending_key; /* map: the key waiting for its value */
  int kline, kcol;
  char path[512];
} frame;

static void frame_path(const frame *st, int depth, char *out, size_t len) {
  /* the key path of the innermost value being parsed, for syntax errors */
  out[0] = '\0';
  for (int i = 0; i < depth; ++i) {
    const wf_node *n = st[i].node;
    char seg[128] = "";
    if (n->kind == WF_MAP && st[i].pending_key)
      snprintf(seg, sizeof seg, "%s", st[i].pending_key);
    else if (n->kind == WF_MAP && n->n > 0)
      snprintf(seg, sizeof seg, "%s", n->keys[n->n - 1]);
    else if (n->kind == WF_SEQ)
      snprintf(seg, sizeof seg, "%d", n->n);
    if (!seg[0]) continue;
    const size_t l = strlen(out);
    snprintf(out + l, len - l, "%s%s", l ? "." : "", seg);
  }
}

/* Parse YAML text into a tree.  origin names the source in messages. */
static wf_node *parse_yaml(const unsigned char *text, size_t len, const char *origin, char *msg,
                           size_t msglen) {
  yaml_parser_t parser;
  if (!yaml_parser_initialize(&parser)) {
    snprintf(msg, msglen, "%s: cannot initialise the YAML parser", origin);
    return NULL;
  }
  yaml_parser_set_input_string(&parser, text, len);
  frame st[WF_DEPTH];
  int depth = 0, done = 0, ndoc = 0;
  wf_node *root = NULL;
  while (!done) {
    yaml_event_t ev;
    if (!yaml_parser_parse(&parser, &ev)) {
      char where[512];
      frame_path(st, depth, where, sizeof where);
      const yaml_mark_t mk = parser.problem_mark;
      snprintf(msg, msglen, "%s:%zu:%zu: %skey '%s': YAML syntax error: %s%s%s", origin,
               mk.line + 1, mk.column + 1, "", where[0] ? where : "(top level)",
               parser.problem ? parser.problem : "unknown problem",
               parser.context ? " " : "", parser.context ? parser.context : "");
      goto fail;
    }
    const int line = (int)ev.start_mark.line + 1, col = (int)ev.start_mark.column + 1;
    wf_node *made = NULL;
    switch (ev.type) {
      case YAML_STREAM_END_EVENT: done = 1; break;
      case YAML_DOCUMENT_START_EVENT:
        if (++ndoc > 1) {
          snprintf(msg, msglen, "%s:%d:%d: key '(top level)': a scene is a single YAML document",
                   origin, line, col);
          yaml_event_delete(&ev);
          goto fail;
        }
        break;
      case YAML_ALIAS_EVENT: {
        char where[512];
        frame_path(st, depth, where, sizeof where);
        snprintf(msg, msglen, "%s:%d:%d: key '%s': YAML aliases (*name) are not supported", origin,
                 line, col, where);
        yaml_event_delete(&ev);
        goto fail;
      }
      case YAML_SCALAR_EVENT:
        if (depth > 0 && st[depth - 1].node->kind == WF_MAP && !st[depth - 1].pending_key) {
          frame *f = &st[depth - 1];
          const char *k = (const char *)ev.data.scalar.value;
          if (map_index(f->node, k) >= 0) {
            char where[512];
            frame_path(st, depth, where, sizeof where);
            snprintf(msg, msglen, "%s:%d:%d: key '%s%s%s': duplicate key", origin, line, col, where,
                     where[0] ? "." : "", k);
            yaml_event_delete(&ev);
            goto fail;
          }
          f->pending_key = strdup(k);
          f->kline = line;
          f->kcol = col;
          break;
        }
        made = node_new(WF_SCALAR, line, col, origin);
        if (made) {
          made->value = strdup((const char *)ev.data.scalar.value);
          made->quoted = ev.data.scalar.style == YAML_SINGLE_QUOTED_SCALAR_STYLE ||
                         ev.data.scalar.style == YAML_DOUBLE_QUOTED_SCALAR_STYLE;
        }
        break;
      case YAML_SEQUENCE_START_EVENT:
        /* a list in a key's place ("[a, b]: c", found by fuzzing): keys are plain scalars */
        if (depth > 0 && st[depth - 1].node->kind == WF_MAP && !st[depth - 1].pending_key) {
          snprintf(msg, msglen, "%s:%d:%d: key '(complex)': only plain scalar keys are supported",
                   origin, line, col);
          yaml_event_delete(&ev);
          goto fail;
        }
        made = node_new(WF_SEQ, line, col, origin);
        break;
      case YAML_MAPPING_START_EVENT:
        if (depth > 0 && st[depth - 1].node->kind == WF_MAP && !st[depth - 1].pending_key) {
          snprintf(msg, msglen, "%s:%d:%d: key '(complex)': only plain scalar keys are supported",
                   origin, line, col);
          yaml_event_delete(&ev);
          goto fail;
        }
        made = node_new(WF_MAP, line, col, origin);
        break;
      case YAML_SEQUENCE_END_EVENT:
      case YAML_MAPPING_END_EVENT: depth--; break;
      default: break;
    }
    const int opens = ev.type == YAML_SEQUENCE_START_EVENT || ev.type == YAML_MAPPING_START_EVENT;
    const int is_value = opens || (ev.type == YAML_SCALAR_EVENT && made);
    yaml_event_delete(&ev);
    if (is_value) {
      if (!made) {
        snprintf(msg, msglen, "%s: out of memory", origin);
        goto fail;
      }
      if (depth == 0) {
        root = made;
      } else {
        frame *f = &st[depth - 1];
        int err = node_push(f->node, f->pending_key, f->kline, f->kcol, made);
        free(f->pending_key);
        f->pending_key = NULL;
        if (err) {
          wf_node_free(made);
          snprintf(msg, msglen, "%s: out of memory", origin);
          goto fail;
        }
      }
      if (opens) {
        if (depth == WF_DEPTH) {
          snprintf(msg, msglen, "%s:%d:%d: key '(deep)': nesting deeper than %d levels", origin,
                   line, col, WF_DEPTH);
          goto fail;
        }
        st[depth].node = made;
        st[depth].pending_key = NULL;
        depth++;
      }
    }
  }
  yaml_parser_delete(&parser);
  if (!root) root = node_new(WF_MAP, 1, 1, origin); /* empty document */
  return root;
fail:
  for (int i = 0; i < depth; ++i) free(st[i].pending_key);
  yaml_parser_delete(&parser);
  wf_node_free(root);
  return NULL;
}


/** @brief The key path path.key ("stages.0" + "end" -> "stages.0.end"; key alone at the top). */
void wf_key_join(char *out, size_t len, const char *path, const char *key) {
  snprintf(out, len, "%s%s%s", path, path[0] ? "." : "", key);
}

/* ---- --set overrides ------------------------------------------------------------------- */
/**
 * @brief Apply one `--set key.path=value` override to the tree; the nodes it makes name
 *        origin (which must outlive the tree) in messages.  0, or -1 with msg.
 */
int wf_yaml_override(wf_node *root, const char *arg, const char *origin, char *msg, size_t len) {
  const char *eq = strchr(arg, '=');
  if (!eq || eq == arg) {
    snprintf(msg, len, "--set %s: key '%s': expected key.path=value", arg, arg);
    return -1;
  }
  char path[512];
  const size_t pl = (size_t)(eq - arg);
  if (pl >= sizeof path) {
    snprintf(msg, len, "--set %s: key path too long", arg);
    return -1;
  }
  memcpy(path, arg, pl);
  path[pl] = '\0';
  const char *val = eq + 1;
  wf_node *value = parse_yaml((const unsigned char *)val, strlen(val), origin, msg, len);
  if (!value) return -1;
  /* the value's nodes report the --set argument as their origin, without line numbers */
  wf_node *stack[WF_DEPTH];
  int sp = 0;
  stack[sp++] = value;
  while (sp) {
    wf_node *n = stack[--sp];
    n->line = 0;
    for (int i = 0; i < n->n && sp < WF_DEPTH; ++i) stack[sp++] = n->items[i];
  }
  if (value->kind == WF_MAP && value->n == 0 && !val[0]) {
    wf_node_free(value);
    snprintf(msg, len, "--set %s: key '%s': empty value", arg, path);
    return -1;
  }
  wf_node *cur = root;
  char *save = NULL;
  char *seg = strtok_r(path, ".", &save);
  char done[512] = "";
  while (seg) {
    char *next = strtok_r(NULL, ".", &save);
    char sofar[512];
    wf_key_join(sofar, sizeof sofar, done, seg);
    if (cur->kind == WF_MAP) {
      int i = map_index(cur, seg);
      if (!next) {
        if (i >= 0) {
          wf_node_free(cur->items[i]);
          cur->items[i] = value;
        } else if (node_push(cur, seg, 0, 0, value)) {
          wf_node_free(value);
          snprintf(msg, len, "out of memory");
          return -1;
        }
        return 0;
      }
      if (i < 0) {
        wf_node *m = node_new(WF_MAP, 0, 0, origin);
        if (!m || node_push(cur, seg, 0, 0, m)) {
          wf_node_free(m);
          wf_node_free(value);
          snprintf(msg, len, "out of memory");
          return -1;
        }
        i = cur->n - 1;
      }
      cur = cur->items[i];
    } else if (cur->kind == WF_SEQ) {
      int idx = -1;
      char *end;
      const long l = strtol(seg, &end, 10);
      if (!*end && l >= 0 && l < cur->n) idx = (int)l;
      for (int i = 0; idx < 0 && i < cur->n; ++i) {
        const wf_node *nm = wf_map_get(cur->items[i], "name");
        if (nm && nm->kind == WF_SCALAR && !strcmp(nm->value, seg)) idx = i;
      }
      if (idx < 0) {
        snprintf(msg, len, "--set %s: key '%s': no list item '%s' (give an index 0..%d or a name)",
                 arg, sofar, seg, cur->n - 1);
        wf_node_free(value);
        return -1;
      }
      if (!next) {
        wf_node_free(cur->items[idx]);
        cur->items[idx] = value;
        return 0;
      }
      cur = cur->items[idx];
    } else {
      snprintf(msg, len, "--set %s: key '%s': is a value, it has no key '%s'", arg, done, seg);
      wf_node_free(value);
      return -1;
    }
    snprintf(done, sizeof done, "%s", sofar);
    seg = next;
  }
  wf_node_free(value);
  snprintf(msg, len, "--set %s: key '': empty key path", arg);
  return -1;
}

/**
 * @brief Parse a YAML (or JSON) file into a tree; NULL with *code (MPMC_ERR_IO, _MEMORY or
 *        _FORMAT) and a message naming the file (and line and column) on failure; `what`
 *        names the file in the message ("scene file").
 */
wf_node *wf_yaml_load(const char *path, const char *what, int *code, char *msg, size_t len) {
  FILE *f = fopen(path, "rb");
  if (!f) {
    snprintf(msg, len, "%s: cannot open the %s: %s", path, what, strerror(errno));
    *code = MPMC_ERR_IO;
    return NULL;
  }
  size_t cap = 1 << 16, n = 0;
  unsigned char *text = malloc(cap);
  while (text) {
    n += fread(text + n, 1, cap - n, f);
    if (n < cap) break;
    unsigned char *t = realloc(text, cap * 2);
    if (!t) {
      free(text);
      text = NULL;
      break;
    }
    text = t;
    cap *= 2;
  }
  fclose(f);
  if (!text) {
    snprintf(msg, len, "%s: out of memory", path);
    *code = MPMC_ERR_MEMORY;
    return NULL;
  }
  wf_node *root = parse_yaml(text, n, path, msg, len);
  free(text);
  *code = root ? 0 : MPMC_ERR_FORMAT;
  return root;
}
