#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sexp.h"
#include "alloc.h"

typedef struct {
    const char *s;
    int line;
    char *err;
    int errlen;
    int depth;
} reader;

enum { MAX_DEPTH = 64 };

static sx *fail(reader *r, const char *what)
{
    if (r->err[0] == 0)
        snprintf(r->err, r->errlen, "line %d: %s", r->line, what);
    return NULL;
}

static void skip_space(reader *r)
{
    for (;;) {
        if (*r->s == '\n')
            r->line++;
        if (isspace((unsigned char)*r->s))
            r->s++;
        else if (*r->s == ';')
            while (*r->s && *r->s != '\n')
                r->s++;
        else
            return;
    }
}

static sx *make(enum sexp_kind kind)
{
    sx *x = xcalloc(1, sizeof *x);
    if (!x) {
        perror("b14");
        exit(1);
    }
    x->kind = kind;
    return x;
}

static sx *read_datum(reader *r);

static sx *read_list(reader *r)
{
    sx *list = make(SX_LIST), **tail = &list->head;
    if (++r->depth > MAX_DEPTH) {
        sx_free(list);
        return fail(r, "nested too deeply");
    }
    r->s++;
    for (;;) {
        skip_space(r);
        if (*r->s == ')') {
            r->s++;
            r->depth--;
            return list;
        }
        if (*r->s == 0 || !(*tail = read_datum(r))) {
            sx_free(list);
            return fail(r, "unclosed (");
        }
        tail = &(*tail)->next;
    }
}

static sx *read_string(reader *r)
{
    const char *start = ++r->s;
    sx *x;
    char *out;
    while (*r->s && *r->s != '"')
        r->s += (*r->s == '\\' && r->s[1]) ? 2 : 1;
    if (*r->s != '"')
        return fail(r, "unclosed string");
    x = make(SX_STRING);
    x->text = out = xmalloc(r->s - start + 1);
    for (; start < r->s; start++)
        *out++ = *start == '\\' ? *++start : *start;
    *out = 0;
    r->s++;
    return x;
}

static int delimiter(char c)
{
    return c == 0 || isspace((unsigned char)c) || c == '(' || c == ')' || c == '"' || c == ';';
}

static sx *read_atom(reader *r)
{
    const char *start = r->s;
    size_t n;
    char *end;
    sx *x;
    while (!delimiter(*r->s))
        r->s++;
    n = r->s - start;
    if (n == 2 && (start[1] == 't' || start[1] == 'f') && start[0] == '#') {
        x = make(SX_BOOL);
        x->num = start[1] == 't';
        return x;
    }
    x = make(SX_NUMBER);
    x->num = strtod(start, &end);
    if (end == r->s && n > 0 && !isalpha((unsigned char)start[n - 1]))
        return x;
    x->kind = SX_SYMBOL;
    x->text = xstrndup(start, n);
    return x;
}

static sx *read_datum(reader *r)
{
    skip_space(r);
    switch (*r->s) {
    case 0: return fail(r, "end of file where a datum was expected");
    case '(': return read_list(r);
    case ')': return fail(r, "unexpected )");
    case '"': return read_string(r);
    case '\'': return fail(r, "quote is not lab syntax");
    default: return read_atom(r);
    }
}

sx *sx_read(const char *text, char *err, int errlen)
{
    reader r = { text, 1, err, errlen, 0 };
    err[0] = 0;
    return read_datum(&r);
}

/* Read in pieces, so that a pipe or a /proc file, whose size is not known
 * beforehand, reads as well as a plain file, and a directory is refused. */
sx *sx_read_file(const char *path, char *err, int errlen)
{
    FILE *f = fopen(path, "r");
    char *text = NULL;
    size_t n = 0, cap = 0;
    int failed;
    sx *x;
    if (!f) {
        snprintf(err, errlen, "%s: cannot open", path);
        return NULL;
    }
    do {
        if (cap - n < 4096)
            text = xrealloc(text, cap = 2 * cap + 4096);
        n += fread(text + n, 1, cap - n - 1, f);
    } while (!feof(f) && !ferror(f));
    failed = ferror(f);
    fclose(f);
    if (failed) {
        snprintf(err, errlen, "%s: cannot read", path);
        free(text);
        return NULL;
    }
    text[n] = 0;
    x = sx_read(text, err, errlen);
    free(text);
    return x;
}

void sx_free(sx *x)
{
    while (x) {
        sx *next = x->next;
        sx_free(x->head);
        free(x->text);
        free(x);
        x = next;
    }
}

int sx_is(const sx *x, const char *symbol)
{
    return x && x->kind == SX_SYMBOL && strcmp(x->text, symbol) == 0;
}

const sx *sx_nth(const sx *list, int n)
{
    const sx *x = list && list->kind == SX_LIST ? list->head : NULL;
    while (x && n-- > 0)
        x = x->next;
    return x;
}

int sx_length(const sx *list)
{
    int n = 0;
    const sx *x;
    for (x = list->head; x; x = x->next)
        n++;
    return n;
}

const sx *sx_clause(const sx *list, const char *symbol, const sx *after)
{
    const sx *x = after ? after->next : sx_nth(list, 0);
    for (; x; x = x->next)
        if (x->kind == SX_LIST && sx_is(x->head, symbol))
            return x;
    return NULL;
}
