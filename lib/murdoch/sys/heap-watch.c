/*  heap-watch.c -- the C of (murdoch sys guard): the heap's ceiling
 *
 *  Received code can ask for any amount of memory, and Chibi's own
 *  ceiling (-h SIZE/MAX) does not hold it: the heap grows whenever it is
 *  under MAX, by as much as one allocation asks, so (make-vector 100000000)
 *  takes 800 MB at once; and once live data fills the ceiling, each
 *  allocation that fails answers an exception object instead of raising,
 *  after a full collection, so a loop that conses runs on for ever in
 *  collections.  Neither can be answered with an error.  So an address
 *  space ends itself when its heap passes the lab's heap-max, with a line
 *  that says so, and the lab starts it again (bin/murdoch-lab).
 *
 *  The look is made by an OS thread of its own, twice a second, so that it
 *  comes even while the VM is inside one long allocation or collection.
 *  It reads only the heaps' sizes, which the VM writes as it grows them;
 *  a size read mid-write is at worst one look late.
 *
 *  guard.stub binds it, and chibi-ffi makes the binding's C.
 */

#include <chibi/eval.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <stdint.h>
#include <unistd.h>

static sexp_heap watched;
static size_t ceiling;
static char message[256];

static size_t heap_bytes (void) {
  size_t total = 0;
  sexp_heap h;
  for (h = watched; h; h = h->next)
    total += h->size;
  return total;
}

static void *watch (void *unused) {
  for (;;) {
    usleep(500000);
    if (heap_bytes() > ceiling) {
      ssize_t ignored = write(2, message, strlen(message));
      (void)ignored;
      _exit(3);
    }
  }
  return NULL;
}

/* (start-heap-guard! bytes line): ends the process, writing line to
 * standard error, once its heap passes bytes.  Once per process. */
static sexp start_heap_guard (sexp ctx, sexp self, long bytes,
                              const char *line) {
  pthread_t thread;
  pthread_attr_t attr;
  sigset_t all, old;
  int started;
  if (bytes <= 0)
    return sexp_user_exception(ctx, self, "not a heap size",
                               sexp_make_integer(ctx, bytes));
  if (watched)
    return sexp_user_exception(ctx, self, "the heap guard is already on",
                               SEXP_FALSE);
  ceiling = bytes;
  snprintf(message, sizeof message, "%s\n", line);
  watched = sexp_context_heap(ctx);
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, 64 * 1024);
  /* The watcher is made with every signal blocked, which it keeps: a
   * signal for the process is the VM's to handle, on its own thread. */
  sigfillset(&all);
  pthread_sigmask(SIG_BLOCK, &all, &old);
  started = pthread_create(&thread, &attr, watch, NULL) == 0;
  pthread_sigmask(SIG_SETMASK, &old, NULL);
  pthread_attr_destroy(&attr);
  if (!started) {
    watched = NULL;
    return sexp_user_exception(ctx, self, "cannot start the heap guard",
                               SEXP_FALSE);
  }
  pthread_detach(thread);
  return SEXP_VOID;
}

/* (heap-on-huge-pages!): moves the heap onto 2 MB pages now.  An address
 * space forked from the lab's loader shares the loader's heap, and the
 * first write to each shared huge page splits it into 4 KB pages: every
 * address space of a lab ran on 4 KB pages, which tools/chibi asks glibc
 * to avoid (it says why).  The collector's first marks copy nearly all the
 * heap anyway, so moving it costs no memory; and until they have, the
 * kernel does not collapse it (pages still shared with the loader: called
 * at the fork, a lab of 16 had 2 to 8 MB of its 32 on 2 MB pages, called
 * after the join 26 to 30).  MADV_COLLAPSE is Linux 6.1's;
 * answers #f when the kernel cannot, which leaves the heap as it was. */
#ifndef MADV_COLLAPSE
#define MADV_COLLAPSE 25
#endif
#define HUGE_PAGE ((uintptr_t)2 * 1024 * 1024)

static sexp heap_on_huge_pages (sexp ctx, sexp self) {
  sexp_heap h;
  int all = 1;
  for (h = sexp_context_heap(ctx); h; h = h->next) {
    uintptr_t from = ((uintptr_t)h->data + HUGE_PAGE - 1) & ~(HUGE_PAGE - 1);
    uintptr_t to = ((uintptr_t)h->data + h->size) & ~(HUGE_PAGE - 1);
    if (to > from && madvise((void *)from, to - from, MADV_COLLAPSE) != 0)
      all = 0;
  }
  return sexp_make_boolean(all);
}
