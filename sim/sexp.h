/* A small reader for the lab file: lists, symbols, strings, numbers, #t/#f
 * and ; comments -- the part of Scheme's external syntax a lab file uses. */
#ifndef SEXP_H
#define SEXP_H

enum sexp_kind { SX_LIST, SX_SYMBOL, SX_STRING, SX_NUMBER, SX_BOOL };

typedef struct sx {
    enum sexp_kind kind;
    double num;          /* SX_NUMBER; SX_BOOL: 0 or 1 */
    char *text;          /* SX_SYMBOL, SX_STRING */
    struct sx *head;     /* SX_LIST: first element */
    struct sx *next;     /* next element of the enclosing list */
} sx;

/* Read the first datum of text; NULL with a message in err on failure. */
sx *sx_read(const char *text, char *err, int errlen);
sx *sx_read_file(const char *path, char *err, int errlen);
void sx_free(sx *x);

int sx_is(const sx *x, const char *symbol);      /* a symbol named so */
const sx *sx_nth(const sx *list, int n);         /* NULL when too short */
int sx_length(const sx *list);
/* The first element of list that is a list headed by symbol, after skip. */
const sx *sx_clause(const sx *list, const char *symbol, const sx *after);
#endif
