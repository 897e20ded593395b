/*  scheduler.c -- wait on descriptors instead of napping when all threads block
 *
 *  Chibi's SRFI 18 scheduler, when no thread can run, naps 10 ms and looks
 *  again: a thread blocked on a socket sees its data up to 10 ms late, so a
 *  request/reply between two Chibi processes costs about 11 ms.  This module
 *  puts a wrapper in front of that scheduler.  When the wrapper sees that no
 *  thread can run, it waits in ppoll() on the descriptors the blocked threads
 *  wait on, until the nearest thread's deadline, and only then hands over to
 *  Chibi's scheduler, which finds something ready and so never naps.
 *
 *  The wrapper changes four things besides: it takes out of the run queue
 *  any second copy of a thread (see unqueue_twins), it gives the thread it
 *  hands over a longer time slice (QUANTUM), it resumes a context inside a
 *  call from C only in that call's own run of the VM (see Homes), it
 *  wakes a blocked thread that is interrupted (see Interrupts), and it
 *  stops a thread whose stack nears Chibi's limit (see The stack guard).
 *  Everything it reads or writes -- the paused list, the run queue, each
 *  thread's wait flag, deadline, event, fuel and interrupt mark -- is
 *  public in sexp.h.
 *
 *  Written by hand, not made from a .stub by chibi-ffi as the other
 *  libraries' C is: its heart is an opcode that the VM calls in its own
 *  convention, and loading must install it or fail, which a stub cannot say.
 */

#include <chibi/eval.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#if ! SEXP_USE_GREEN_THREADS
#error "(murdoch sys scheduler) needs a Chibi-Scheme built with green threads"
#endif

/* What one look at the blocked threads decided. */
enum wait_result {
  WAIT_AGAIN,      /* a deadline came or a signal broke in: look again */
  WAIT_DONE        /* something is ready, or there is nothing to wait on */
};

/* The time slice, in VM instructions, that the wrapper gives each thread
 * it hands over: Chibi's is 500.  Chibi's scheduler polls every descriptor
 * a thread waits on each time it runs, so with 64 connections a process
 * spent a third of its time in poll(); ten times fewer slices cut a
 * request to 64 address spaces from 20 to 15 ms.  A slice of 5000 is
 * still some tens of microseconds. */
#ifndef QUANTUM
#define QUANTUM 5000
#endif

/* One array reused for every wait; the process has one OS thread. */
static struct pollfd *pollfds;
static size_t pollfds_size;

/* Chibi leaves the deadline at zero for a wait without timeout. */
static int has_deadline (sexp thread) {
  return sexp_context_timeval(thread).tv_sec != 0
    || sexp_context_timeval(thread).tv_usec != 0;
}

/* Chibi leaves the microseconds of a deadline in the past negative, so
 * deadlines are compared as counts of microseconds, not field by field. */
static long long microseconds (const struct timeval *t) {
  return (long long)t->tv_sec * 1000000 + t->tv_usec;
}

static int before (const struct timeval *a, const struct timeval *b) {
  return microseconds(a) < microseconds(b);
}

/* The descriptor a thread is blocked on, as Chibi's blocker registered it:
 * ports and plain integers only, output ports for writing.  Returns -1 when
 * the thread waits on something else.  A closed port's stream is freed, so
 * it must not be asked for its descriptor. */
static int blocked_fd (sexp thread, short *events) {
  sexp event = sexp_context_event(thread);
  if (sexp_fixnump(event)) {
    *events = POLLIN;
    return sexp_unbox_fixnum(event);
  }
  if (sexp_portp(event) && sexp_port_openp(event)) {
    *events = sexp_oportp(event) ? POLLOUT : POLLIN;
    return sexp_port_fileno(event);
  }
  return -1;
}

static int ensure_pollfds (size_t n) {
  struct pollfd *grown;
  size_t size = pollfds_size ? pollfds_size : 16;
  if (n <= pollfds_size) return 1;
  while (size < n) size *= 2;
  grown = realloc(pollfds, size * sizeof(*grown));
  if (!grown) return 0;
  pollfds = grown;
  pollfds_size = size;
  return 1;
}

static int waits_on (sexp thread, sexp target) {
  return sexp_context_event(thread) == target;
}

/* Whether Chibi's scheduler, called now, would find nothing to run:
 * nothing in the run queue, no signal to deliver, and the thread it would
 * pick is waiting.  Errs towards "no": a wrong "yes" could block the
 * process. */
static int nothing_runnable (sexp ctx) {
  sexp ls, paused = sexp_global(ctx, SEXP_G_THREADS_PAUSED);
  if (sexp_global(ctx, SEXP_G_THREADS_SIGNALS) != SEXP_ZERO
      || sexp_pairp(sexp_global(ctx, SEXP_G_THREADS_FRONT)))
    return 0;
  if (sexp_context_refuel(ctx) > 0)
    return sexp_context_waitp(ctx);
  /* The current thread has ended.  Chibi wakes the threads joining it;
   * failing those it hands back a blocked thread after a nap, or the ended
   * thread itself, and then the VM calls it again at once: a spin at full
   * CPU until some deadline, which waiting here replaces. */
  for (ls = paused; sexp_pairp(ls); ls = sexp_cdr(ls))
    if (waits_on(sexp_car(ls), ctx))
      return 0;
  return 1;
}

/* Add a blocked thread's descriptor and deadline to the wait; 0 when the
 * array cannot grow. */
static int note_waiter (sexp thread, nfds_t *n, struct timeval **deadline) {
  short events;
  int fd = blocked_fd(thread, &events);
  if (fd >= 0) {
    if (!ensure_pollfds(*n + 1)) return 0;
    pollfds[*n].fd = fd;
    pollfds[*n].events = events;
    pollfds[*n].revents = 0;
    ++*n;
  }
  if (has_deadline(thread)
      && (!*deadline || before(&sexp_context_timeval(thread), *deadline)))
    *deadline = &sexp_context_timeval(thread);
  return 1;
}

/* The time from now until just past the deadline; 0 when it has passed. */
static int time_until (const struct timeval *deadline, struct timespec *ts) {
  struct timeval now;
  long long usecs;
  if (gettimeofday(&now, NULL) != 0)
    return 0;
  usecs = microseconds(deadline) - microseconds(&now) + 1;
  if (usecs <= 0)
    return 0;
  ts->tv_sec = usecs / 1000000;
  ts->tv_nsec = (usecs % 1000000) * 1000;
  return 1;
}

/* Sleep until a blocked thread's descriptor is ready, the nearest deadline
 * passes or a signal arrives.  Signals are blocked by the caller and let in
 * only inside ppoll(), so one arriving after the caller's check cannot be
 * slept through.  With nothing to wait on, leave it to Chibi, which naps. */
static enum wait_result wait_once (sexp ctx, const sigset_t *mask) {
  sexp ls;
  nfds_t n = 0;
  int paused = 0;
  struct timeval *deadline = NULL;
  struct timespec timeout;
  for (ls = sexp_global(ctx, SEXP_G_THREADS_PAUSED); sexp_pairp(ls);
       ls = sexp_cdr(ls)) {
    paused |= sexp_car(ls) == ctx;
    if (!note_waiter(sexp_car(ls), &n, &deadline))
      return WAIT_DONE;
  }
  /* Chibi's nap takes the current thread off the paused list; a thread
   * that blocks is on it already, and its descriptor is polled once. */
  if (sexp_context_waitp(ctx) && !paused && !note_waiter(ctx, &n, &deadline))
    return WAIT_DONE;
  if (n == 0 && !deadline)
    return WAIT_DONE;
  if (deadline && !time_until(deadline, &timeout))
    return WAIT_DONE;
  switch (ppoll(pollfds, n, deadline ? &timeout : NULL, mask)) {
  case 0:
    return WAIT_AGAIN;
  case -1:
    return errno == EINTR ? WAIT_AGAIN : WAIT_DONE;
  default:
    return WAIT_DONE;
  }
}

/* Takes cell, which follows prev (SEXP_NULL when cell is first), out of
 * the list that the global slot list holds: the run queue or the paused
 * list.  The caller sees to the run queue's back and to cell's cdr. */
static void unlink_cell (sexp ctx, int list, sexp prev, sexp cell) {
  if (sexp_pairp(prev))
    sexp_cdr(prev) = sexp_cdr(cell);
  else
    sexp_global(ctx, list) = sexp_cdr(cell);
}

/* Wakes the context of cell, taken out of the paused list, as Chibi wakes
 * a thread whose mutex was unlocked: it runs again at the back of the run
 * queue, and only tries again what it was waiting for. */
static void queue_cell (sexp ctx, sexp cell) {
  sexp_context_waitp(sexp_car(cell)) = 0;
  sexp_context_timeoutp(sexp_car(cell)) = 0;
  sexp_cdr(cell) = SEXP_NULL;
  if (sexp_pairp(sexp_global(ctx, SEXP_G_THREADS_BACK)))
    sexp_cdr(sexp_global(ctx, SEXP_G_THREADS_BACK)) = cell;
  else
    sexp_global(ctx, SEXP_G_THREADS_FRONT) = cell;
  sexp_global(ctx, SEXP_G_THREADS_BACK) = cell;
}

/* Interrupts.  Chibi's thread-interrupt! -- the REPL's answer to Ctrl-C --
 * only marks a thread, and the VM raises the interrupt in it when its time
 * slice ends.  A blocked thread has no slice: the REPL waiting for a
 * pose-task went on waiting, and raised only once the task was done.  So
 * before the process sleeps, each paused thread so marked is woken.
 *
 * The VM looks at the mark only before an instruction, when the fuel has
 * run out, and a woken thread resumes at the instruction that blocked,
 * which a read tries again at once, and blocks again, before the look.
 * So an interrupted thread is handed over as if it still waited, with one
 * instruction of fuel: the VM then looks before anything else, and raises
 * inside the call that blocked.  One instruction later the scheduler sees
 * it back and takes the wait off (see interrupt_raised). */
static void wake_interrupted (sexp ctx) {
  sexp prev = SEXP_NULL, ls = sexp_global(ctx, SEXP_G_THREADS_PAUSED), next;
  for ( ; sexp_pairp(ls); ls = next) {
    next = sexp_cdr(ls);
    if (sexp_context_interruptp(sexp_car(ls))
        && sexp_context_refuel(sexp_car(ls)) > 0) {
      unlink_cell(ctx, SEXP_G_THREADS_PAUSED, prev, ls);
      queue_cell(ctx, ls);
    } else {
      prev = ls;
    }
  }
}

/* Gives a thread it hands over its fuel: a whole slice, or for one marked
 * for an interrupt the one instruction of wake_interrupted. */
static void hand_over (sexp c) {
  if (sexp_context_interruptp(c)) {
    sexp_context_waitp(c) = 1;
    sexp_context_refuel(c) = 1;
  } else {
    sexp_context_refuel(c) = QUANTUM;
  }
}

/* A thread back from raising its interrupt was handed over as waiting;
 * no other keeps a fuel of one. */
static void interrupt_raised (sexp ctx) {
  if (sexp_context_refuel(ctx) == 1 && !sexp_context_interruptp(ctx))
    sexp_context_waitp(ctx) = 0;
}

static void wait_for_wakeup (sexp ctx) {
  enum wait_result result = WAIT_AGAIN;
  sigset_t all, old;
  sigfillset(&all);
  wake_interrupted(ctx);
  if (sigprocmask(SIG_BLOCK, &all, &old) != 0)
    return;
  while (result == WAIT_AGAIN && nothing_runnable(ctx))
    result = wait_once(ctx, &old);
  sigprocmask(SIG_SETMASK, &old, NULL);
}

/* Chibi's timeout sweep queues every paused thread whose deadline has
 * passed, the current one too, although the current one then goes on
 * running, or is put in the queue a second time: it would be resumed twice,
 * the second time perhaps after it has ended, which crashes the VM.
 * Chibi's own naps make this rare, since a thread seldom outlives its own
 * deadline; with the wrapper it would follow most thread-sleep! calls.  So
 * keep the thread that runs next out of the queue, and the one that ran
 * before in it at most once. */
static void unqueue_twins (sexp previous, sexp next) {
  sexp prev = SEXP_NULL, ls = sexp_global(previous, SEXP_G_THREADS_FRONT);
  int seen = 0;
  for ( ; sexp_pairp(ls); ls = sexp_cdr(ls)) {
    if (sexp_car(ls) == next || (sexp_car(ls) == previous && seen++)) {
      unlink_cell(previous, SEXP_G_THREADS_FRONT, prev, ls);
    } else {
      prev = ls;
    }
  }
  sexp_global(previous, SEXP_G_THREADS_BACK) = prev;
}

/* Homes.
 *
 * Scheme that C calls -- eval, a sort's comparator -- runs in a new run of
 * the VM, on the C stack above the caller's, whose root is the context
 * making the call (eval makes a fresh one).  Threads are switched inside
 * it as anywhere, and Chibi resumes any context in whatever run of the VM
 * is innermost.  A root resumed in a run not its own goes wrong when its
 * call returns: that VM takes it for a thread that has ended, so the C
 * caller never gets its value, the thread waiting on it is lost, and the
 * root's own run, lower on the C stack, never returns.  Chibi's own
 * scheduler does the same: four threads that sort with a Scheme
 * comparator hang within seconds.
 *
 * So a context switched away from while it is the root of the innermost
 * run is homed: it runs again only when the scheduler is called from its
 * own run, i.e. with it as root.  A homed context made runnable meanwhile
 * is parked on the paused list, waiting on the scheduler itself, where
 * nothing of Chibi's wakes it, until its run is innermost again.  Threads
 * not inside a call from C hold no C state and run in any run of the VM. */
/* A set of contexts: an array, looked through in turn, since it holds
 * few. */
struct contexts {
  sexp *items;
  size_t count, size;
};

static int member (const struct contexts *set, sexp c) {
  size_t i;
  for (i = 0; i < set->count; i++)
    if (set->items[i] == c) return 1;
  return 0;
}

/* Answers 0 when c is not added for want of memory. */
static int add (struct contexts *set, sexp c) {
  sexp *grown;
  if (member(set, c)) return 1;
  if (set->count == set->size) {
    grown = realloc(set->items, (set->size ? 2 * set->size : 8) * sizeof(*grown));
    if (!grown) return 0;
    set->items = grown;
    set->size = set->size ? 2 * set->size : 8;
  }
  set->items[set->count++] = c;
  return 1;
}

/* Answers whether c was there. */
static int take (struct contexts *set, sexp c) {
  size_t i;
  for (i = 0; i < set->count; i++)
    if (set->items[i] == c) {
      set->items[i] = set->items[--set->count];
      return 1;
    }
  return 0;
}

static struct contexts homes;
static size_t parked_count;

static int homed (sexp c) { return member(&homes, c); }

/* A context that cannot be homed, for want of memory, runs anywhere, as
 * under Chibi's own scheduler. */
static void home (sexp c) { add(&homes, c); }

static void unhome (sexp c) { take(&homes, c); }

/* Whether c may run in the run of the VM whose root is root.  An ended
 * context only ends, which it can do anywhere. */
static int may_run_in (sexp c, sexp root) {
  return c == root || sexp_context_refuel(c) <= 0 || !homed(c);
}

/* Wakes the first paused context waiting on event, as a mutex's unlock or
 * a condition variable's signal would have, had it not woken one that is
 * being parked: a woken thread only tries again, so a wake too many is
 * harmless, and one too few could leave a mutex free and its waiters
 * asleep.  Chibi leaves a woken context's event as it was. */
static void pass_on (sexp ctx, sexp self, sexp event) {
  sexp prev = SEXP_NULL, ls = sexp_global(ctx, SEXP_G_THREADS_PAUSED);
  if (!sexp_pointerp(event) || event == self || sexp_portp(event)
      || sexp_contextp(event))
    return;
  for ( ; sexp_pairp(ls); prev = ls, ls = sexp_cdr(ls))
    if (sexp_context_event(sexp_car(ls)) == event) {
      unlink_cell(ctx, SEXP_G_THREADS_PAUSED, prev, ls);
      queue_cell(ctx, ls);
      return;
    }
}

/* Parks the context of cell, taken out of the run queue: it waits on the
 * scheduler (self), with no deadline, at the end of the paused list. */
static void park (sexp ctx, sexp self, sexp cell) {
  sexp ls, c = sexp_car(cell);
  pass_on(ctx, self, sexp_context_event(c));
  ls = sexp_global(ctx, SEXP_G_THREADS_PAUSED);
  sexp_context_waitp(c) = 1;
  sexp_context_event(c) = self;
  sexp_context_timeval(c).tv_sec = 0;
  sexp_context_timeval(c).tv_usec = 0;
  sexp_cdr(cell) = SEXP_NULL;
  if (!sexp_pairp(ls)) {
    sexp_global(ctx, SEXP_G_THREADS_PAUSED) = cell;
  } else {
    while (sexp_pairp(sexp_cdr(ls))) ls = sexp_cdr(ls);
    sexp_cdr(ls) = cell;
  }
  parked_count++;
}

/* Parks every context of the run queue that may not run in root's run;
 * a second copy of one already parked is dropped.  They are taken out of
 * the queue first, since parking one may wake another into it. */
static void park_strangers (sexp ctx, sexp self, sexp root) {
  sexp prev = SEXP_NULL, ls = sexp_global(ctx, SEXP_G_THREADS_FRONT), next;
  sexp strangers = SEXP_NULL;
  for ( ; sexp_pairp(ls); ls = next) {
    next = sexp_cdr(ls);
    if (may_run_in(sexp_car(ls), root)) {
      prev = ls;
      continue;
    }
    unlink_cell(ctx, SEXP_G_THREADS_FRONT, prev, ls);
    sexp_cdr(ls) = strangers;
    strangers = ls;
  }
  sexp_global(ctx, SEXP_G_THREADS_BACK) = prev;
  for (ls = strangers; sexp_pairp(ls); ls = next) {
    next = sexp_cdr(ls);
    if (sexp_context_event(sexp_car(ls)) != self)
      park(ctx, self, ls);
  }
}

/* Puts the contexts parked for root's run at the head of the run queue:
 * its root is the one whose return lets the runs below it go on. */
static void unpark_home (sexp ctx, sexp self, sexp root) {
  sexp prev = SEXP_NULL, ls = sexp_global(ctx, SEXP_G_THREADS_PAUSED), next;
  size_t still = 0;
  for ( ; sexp_pairp(ls); ls = next) {
    next = sexp_cdr(ls);
    if (sexp_context_event(sexp_car(ls)) != self) {
      prev = ls;
    } else if (sexp_car(ls) != root) {
      still++;
      prev = ls;
    } else {
      unlink_cell(ctx, SEXP_G_THREADS_PAUSED, prev, ls);
      sexp_context_waitp(root) = 0;
      sexp_context_event(root) = SEXP_FALSE;
      sexp_cdr(ls) = sexp_global(ctx, SEXP_G_THREADS_FRONT);
      if (!sexp_pairp(sexp_cdr(ls)))
        sexp_global(ctx, SEXP_G_THREADS_BACK) = ls;
      sexp_global(ctx, SEXP_G_THREADS_FRONT) = ls;
    }
  }
  parked_count = still;
}

/* Chibi's poll.  Chibi's scheduler polls every descriptor a thread has
 * waited on, at each call: a thread's every wait and slice.  While a thread
 * can run it is not asked to look again within LOOK_USECS of its last look;
 * the descriptors are hidden from it, their count set to 0, for that call.
 * Its array is threads.c's (Chibi 0.12), known by its type's name. */
#ifndef LOOK_USECS
#define LOOK_USECS 200
#endif

struct chibi_pollfds {
  struct pollfd *fds;
  nfds_t nfds, mfds;
};

static long long last_look;
static sexp_tag_t pollfds_tag;

static long long now_usecs (void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (long long)t.tv_sec * 1000000 + t.tv_nsec / 1000;
}

static struct chibi_pollfds *chibi_pollfds (sexp ctx) {
  sexp p = sexp_global(ctx, SEXP_G_THREADS_POLL_FDS), type;
  if (!sexp_pointerp(p)) return NULL;
  if (!pollfds_tag) {
    type = sexp_object_type(ctx, p);
    if (!(sexp_typep(type) && sexp_stringp(sexp_type_name(type))
          && strcmp(sexp_string_data(sexp_type_name(type)), "pollfds") == 0))
      return NULL;
    pollfds_tag = sexp_pointer_tag(p);
  }
  return sexp_pointer_tag(p) == pollfds_tag
    ? (struct chibi_pollfds *)&p->value : NULL;
}

/* Whether Chibi's pick, called now, is a thread that can run: the front
 * of the queue, or the current thread going on. */
static int runnable_pick (sexp ctx) {
  sexp front = sexp_global(ctx, SEXP_G_THREADS_FRONT);
  if (sexp_pairp(front))
    return !sexp_context_waitp(sexp_car(front));
  return !sexp_context_waitp(ctx) && sexp_context_refuel(ctx) > 0;
}

/* Chibi's scheduler, then the twins out of the queue; see unqueue_twins. */
static sexp chibi_next (sexp ctx, sexp chibi, sexp_sint_t n, sexp root,
                        int may_twin) {
  struct chibi_pollfds *fds = NULL;
  nfds_t hidden = 0;
  long long now = now_usecs();
  sexp next;
  if (now - last_look < LOOK_USECS && runnable_pick(ctx)
      && (fds = chibi_pollfds(ctx)) != NULL) {
    hidden = fds->nfds;
    fds->nfds = 0;
  } else {
    last_look = now;
  }
  next = ((sexp_proc2)sexp_opcode_func(chibi))(ctx, chibi, n, root);
  if (fds && fds->nfds == 0)
    fds->nfds = hidden;
  if (may_twin && sexp_contextp(next))
    unqueue_twins(ctx, next);
  return next;
}

/* Chibi's pick, unless it belongs to another run of the VM: then the
 * first that may run here, waiting for one if need be.  A waiting pick is
 * let through: the VM only calls the scheduler again at once.  Out of
 * memory for parking, the pick runs where it is, as under Chibi. */
static sexp next_here (sexp ctx, sexp self, sexp_sint_t n, sexp root,
                       int may_twin) {
  sexp chibi = sexp_opcode_data(self), front;
  sexp_gc_var2(next, cell);
  sexp_gc_preserve2(ctx, next, cell);
  next = chibi_next(ctx, chibi, n, root, may_twin);
  while (sexp_contextp(next) && !sexp_context_waitp(next)
         && !may_run_in(next, root)) {
    cell = sexp_cons(ctx, next, SEXP_NULL);
    if (!sexp_pairp(cell))
      break;
    park(ctx, self, cell);
    park_strangers(ctx, self, root);
    front = sexp_global(ctx, SEXP_G_THREADS_FRONT);
    if (sexp_pairp(front)) {
      next = sexp_car(front);
      unqueue_twins(ctx, next);
    } else {
      wait_for_wakeup(ctx);
      next = chibi_next(ctx, chibi, n, root, may_twin);
    }
  }
  sexp_gc_release2(ctx);
  return next;
}

/* The stack guard.  A thread whose stack outgrows SEXP_MAX_STACK_SIZE
 * does not raise an error that a handler could catch: the VM leaves its
 * run with "out of stack space", which ends the whole process.  Received
 * code can recurse without end, so at the end of each time slice a thread
 * whose stack holds more than half that limit is interrupted, as
 * thread-interrupt! does, and noted: it raises in its next instruction,
 * inside the call that recursed, whose handler can then answer the call.
 * A slice of QUANTUM instructions grows a stack by far less than the other
 * half.  (stack-guard-tripped? thread) tells the handler why it was
 * interrupted. */
#define STACK_GUARD (SEXP_MAX_STACK_SIZE / 2)

static struct contexts tripped;         /* preserved from the collector */

/* A thread tripped once is not tripped again before its handler has
 * asked why: it may still be deep while the raise unwinds. */
static void guard_stack (sexp ctx) {
  if (sexp_context_top(ctx) <= STACK_GUARD || sexp_context_interruptp(ctx)
      || member(&tripped, ctx) || !add(&tripped, ctx))
    return;
  sexp_preserve_object(ctx, ctx);
  sexp_context_interruptp(ctx) = 1;
}

static sexp stack_guard_trippedp (sexp ctx, sexp self, sexp_sint_t n,
                                  sexp thread) {
  if (!take(&tripped, thread))
    return SEXP_FALSE;
  sexp_release_object(ctx, thread);
  return SEXP_TRUE;
}

/* The scheduler the VM calls at the end of every time slice.  Only a
 * current thread in a timed wait can be swept into the queue, so the queue
 * is walked for twins only then; with nothing homed, a runnable thread
 * costs a few loads. */
static sexp poll_scheduler (sexp ctx, sexp self, sexp_sint_t n, sexp root) {
  sexp next;
  int may_twin, strangers;
  interrupt_raised(ctx);
  guard_stack(ctx);
  may_twin = sexp_context_waitp(ctx) && has_deadline(ctx);
  if (parked_count > 0)
    unpark_home(ctx, self, root);
  /* With root the only context homed, every context may run here. */
  strangers = homes.count > 1 || (homes.count == 1 && homes.items[0] != root);
  if (strangers)
    park_strangers(ctx, self, root);
  if (nothing_runnable(ctx))
    wait_for_wakeup(ctx);
  next = strangers
    ? next_here(ctx, self, n, root, may_twin)
    : chibi_next(ctx, sexp_opcode_data(self), n, root, may_twin);
  if (sexp_context_refuel(ctx) <= 0)
    unhome(ctx);
  else if (ctx == root && next != ctx)
    home(ctx);
  if (next == root)
    unhome(root);
  /* No fuel marks a thread that has ended; it keeps none. */
  if (sexp_contextp(next) && sexp_context_refuel(next) > 0)
    hand_over(next);
  return next;
}

static int installed (sexp ctx) {
  sexp s = sexp_global(ctx, SEXP_G_THREADS_SCHEDULER);
  return sexp_opcodep(s) && sexp_opcode_func(s) == (sexp_proc1)poll_scheduler;
}

/* (others-runnable?): whether another thread waits in the run queue, so
 * that a thread yielding now would let it run before going on. */
static sexp others_runnablep (sexp ctx, sexp self, sexp_sint_t n) {
  return sexp_make_boolean(sexp_pairp(sexp_global(ctx, SEXP_G_THREADS_FRONT)));
}

/* (cpu-contended?): whether this process waited for a CPU, runnable, an
 * eighth or more of the last window of CONTENDED_USECS or more, by the
 * kernel's count (the second field of /proc/self/schedstat, in ns).  Read
 * once a window; #f where the file cannot be read. */
#ifndef CONTENDED_USECS
#define CONTENDED_USECS 10000
#endif

static int schedstat_fd = -1;
static pid_t schedstat_pid;             /* whose file it is: a fork's differs */
static long long window_wall, window_delay;
static int contended;

static long long run_delay_usecs (void) {
  char buf[96];
  ssize_t got;
  char *p;
  /* A fork's inherited number is left open: it may be another's by now. */
  if (schedstat_pid != getpid()) {
    schedstat_pid = getpid();
    schedstat_fd = open("/proc/self/schedstat", O_RDONLY | O_CLOEXEC);
    window_wall = 0;
  }
  if (schedstat_fd < 0) return -1;
  got = pread(schedstat_fd, buf, sizeof buf - 1, 0);
  if (got <= 0) return -1;
  buf[got] = 0;
  p = strchr(buf, ' ');
  return p ? strtoll(p + 1, NULL, 10) / 1000 : -1;
}

static sexp cpu_contendedp (sexp ctx, sexp self, sexp_sint_t n) {
  long long now = now_usecs(), delay;
  if (now - window_wall >= CONTENDED_USECS) {
    delay = run_delay_usecs();
    contended = delay >= 0 && window_wall > 0
      && 8 * (delay - window_delay) >= now - window_wall;
    window_wall = now;
    window_delay = delay;
  }
  return sexp_make_boolean(contended);
}

static sexp poll_scheduler_installedp (sexp ctx, sexp self, sexp_sint_t n) {
  return sexp_make_boolean(installed(ctx));
}

/* Chibi's own scheduler is kept as the wrapper's data, which also keeps the
 * collector from freeing it. */
static sexp install (sexp ctx) {
  sexp chibi = sexp_global(ctx, SEXP_G_THREADS_SCHEDULER), wrapper;
  if (installed(ctx))
    return SEXP_VOID;
  if (!(sexp_opcodep(chibi) && sexp_opcode_func(chibi)))
    return sexp_user_exception(ctx, SEXP_FALSE,
                               "(murdoch sys scheduler): load (srfi 18) first",
                               chibi);
  wrapper = sexp_make_foreign(ctx, "poll-scheduler", 1, 0, "poll_scheduler",
                              (sexp_proc1)poll_scheduler, chibi);
  if (sexp_exceptionp(wrapper))
    return wrapper;
  sexp_global(ctx, SEXP_G_THREADS_SCHEDULER) = wrapper;
  return SEXP_VOID;
}

/* (monotonic-seconds): seconds since some fixed moment, as a flonum, by
 * CLOCK_MONOTONIC.  Deadlines need no calendar: (scheme time)'s
 * current-second converts through TAI tables in exact arithmetic, 5 us a
 * call, and jumps when the wall clock is set. */
static sexp monotonic_seconds (sexp ctx, sexp self, sexp_sint_t n) {
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  return sexp_make_flonum(ctx, now.tv_sec + now.tv_nsec / 1e9);
}

/* (wall-microseconds): microseconds since 1970 by CLOCK_REALTIME, as an
 * exact integer: a moment other hosts can compare, for the multicast
 * sequence.  current-second takes 2 us with warm caches, through TAI
 * tables in exact arithmetic, and every datagram received reads it. */
static sexp wall_microseconds (sexp ctx, sexp self, sexp_sint_t n) {
  struct timespec now;
  clock_gettime(CLOCK_REALTIME, &now);
  return sexp_make_fixnum((sexp_sint_t)now.tv_sec * 1000000
                          + now.tv_nsec / 1000);
}

/* (port-wait! PORT SECONDS): pauses the calling thread until PORT's
 * descriptor is ready (for reading an input port, for writing an output
 * port) or SECONDS have passed, through Chibi's own blocker, as a read
 * that would block does; the thread pauses at its next yield, which the
 * Scheme side makes at once.  For what has no port-level wait of its own:
 * a non-blocking connect ends when its socket turns writable. */
static sexp port_wait (sexp ctx, sexp self, sexp_sint_t n, sexp port,
                       sexp seconds) {
  sexp blocker = sexp_global(ctx, SEXP_G_THREADS_BLOCKER);
  if (!sexp_portp(port))
    return sexp_type_exception(ctx, self, SEXP_IPORT, port);
  if (!sexp_flonump(seconds))
    return sexp_type_exception(ctx, self, SEXP_FLONUM, seconds);
  if (sexp_applicablep(blocker))
    sexp_apply2(ctx, blocker, port, seconds);
  return SEXP_VOID;
}


/* The poller.  One epoll descriptor holds every connection this process
 * has called out on; one green thread waits on it (through an input port
 * on it, which Chibi's blocker and the wrapper's ppoll know), so a process
 * with 64 connections waits on one descriptor, not 64, and no thread
 * waits per connection.  Each connection's bytes are gathered here, in a
 * buffer of its own, as they come, and handed to Scheme a whole netstring
 * at a time: a peer that stalls mid-frame holds up no other.  The checks
 * are read-netstring's (netstring.scm), with its words for each fault. */
struct inbox {
  unsigned char *bytes;
  size_t length, size;
};

static int poller_fd = -1;
static struct inbox *inboxes;           /* by descriptor */
static size_t inbox_count;

#define POLLER_READ 65536
#define POLLER_EVENTS 256

/* (poller-port): an input port on the epoll descriptor, made once, for
 * the poller's thread to wait on as on any port; never read. */
static sexp poller_port (sexp ctx, sexp self, sexp_sint_t n) {
  sexp_gc_var2(fileno, port);
  if (poller_fd >= 0)
    return sexp_user_exception(ctx, self, "the poller has its port", SEXP_NULL);
  poller_fd = epoll_create1(EPOLL_CLOEXEC);
  if (poller_fd < 0)
    return sexp_user_exception(ctx, self, strerror(errno), SEXP_NULL);
  sexp_gc_preserve2(ctx, fileno, port);
  fileno = sexp_make_fileno(ctx, sexp_make_fixnum(poller_fd), SEXP_FALSE);
  port = sexp_exceptionp(fileno) ? fileno
    : sexp_open_input_file_descriptor(ctx, self, 2, fileno, SEXP_FALSE);
  sexp_gc_release2(ctx);
  return port;
}

static struct inbox *inbox_of (int fd) {
  struct inbox *grown;
  size_t count = inbox_count ? inbox_count : 64;
  if ((size_t)fd >= inbox_count) {
    while (count <= (size_t)fd) count *= 2;
    grown = realloc(inboxes, count * sizeof(*grown));
    if (!grown) return NULL;
    memset(grown + inbox_count, 0, (count - inbox_count) * sizeof(*grown));
    inboxes = grown;
    inbox_count = count;
  }
  return &inboxes[fd];
}

static void empty_inbox (int fd) {
  if (fd >= 0 && (size_t)fd < inbox_count) {
    free(inboxes[fd].bytes);
    memset(&inboxes[fd], 0, sizeof(inboxes[fd]));
  }
}

/* (poller-watch! port): the poller watches port's descriptor, with an
 * empty buffer; answers the descriptor. */
static sexp poller_watch (sexp ctx, sexp self, sexp_sint_t n, sexp port) {
  struct epoll_event e;
  int fd;
  if (!sexp_iportp(port))
    return sexp_type_exception(ctx, self, SEXP_IPORT, port);
  fd = sexp_port_fileno(port);
  if (fd < 0 || poller_fd < 0 || !inbox_of(fd))
    return sexp_user_exception(ctx, self, "cannot watch", port);
  empty_inbox(fd);
  memset(&e, 0, sizeof(e));
  e.events = EPOLLIN;
  e.data.fd = fd;
  if (epoll_ctl(poller_fd, EPOLL_CTL_ADD, fd, &e) != 0)
    return sexp_user_exception(ctx, self, strerror(errno), port);
  return sexp_make_fixnum(fd);
}

/* (poller-unwatch! fd), before its port is closed: a closed number may be
 * another connection's next. */
static sexp poller_unwatch (sexp ctx, sexp self, sexp_sint_t n, sexp fd) {
  if (!sexp_fixnump(fd))
    return sexp_type_exception(ctx, self, SEXP_FIXNUM, fd);
  if (poller_fd >= 0)
    epoll_ctl(poller_fd, EPOLL_CTL_DEL, sexp_unbox_fixnum(fd), NULL);
  empty_inbox(sexp_unbox_fixnum(fd));
  return SEXP_VOID;
}

/* (poller-release! fd): stops watching fd but keeps its buffer, for a
 * thread of its own to read on with poller-frames!. */
static sexp poller_release (sexp ctx, sexp self, sexp_sint_t n, sexp fd) {
  if (!sexp_fixnump(fd))
    return sexp_type_exception(ctx, self, SEXP_FIXNUM, fd);
  if (poller_fd >= 0)
    epoll_ctl(poller_fd, EPOLL_CTL_DEL, sexp_unbox_fixnum(fd), NULL);
  return SEXP_VOID;
}

/* (poller-buffered fd): the bytes of a frame not yet whole in fd's
 * buffer. */
static sexp poller_buffered (sexp ctx, sexp self, sexp_sint_t n, sexp fd) {
  long i;
  if (!sexp_fixnump(fd))
    return sexp_type_exception(ctx, self, SEXP_FIXNUM, fd);
  i = sexp_unbox_fixnum(fd);
  return sexp_make_fixnum(i >= 0 && (size_t)i < inbox_count
                          ? (long)inboxes[i].length : 0);
}

/* (poller-ready): the descriptors with something to read, or that ended;
 * never waits. */
static sexp poller_ready (sexp ctx, sexp self, sexp_sint_t n) {
  struct epoll_event events[POLLER_EVENTS];
  int i, k = poller_fd < 0 ? 0
    : epoll_wait(poller_fd, events, POLLER_EVENTS, 0);
  sexp_gc_var1(ls);
  sexp_gc_preserve1(ctx, ls);
  ls = SEXP_NULL;
  for (i = k - 1; i >= 0; i--)
    ls = sexp_cons(ctx, sexp_make_fixnum(events[i].data.fd), ls);
  sexp_gc_release1(ctx);
  return ls;
}

/* The next netstring of the length bytes at p: its payload's start and
 * length, and where the next begins; NULL with *fault unset when more
 * must come, or with *fault saying what is wrong. */
static const unsigned char *next_netstring (const unsigned char *p,
                                            size_t length, size_t most,
                                            size_t *start, size_t *size,
                                            const char **fault) {
  static char words[64];
  size_t i, len = 0;
  *fault = NULL;
  for (i = 0; i < length && p[i] != ':'; i++) {
    if (p[i] < '0' || p[i] > '9') {
      snprintf(words, sizeof words, "non-digit byte %d in length", p[i]);
      *fault = words;
      return NULL;
    }
    if (i == 1 && p[0] == '0') {
      *fault = "leading zero in length";
      return NULL;
    }
    len = len * 10 + (p[i] - '0');
    if (len > most) {
      snprintf(words, sizeof words, "length over %lu bytes",
               (unsigned long)most);
      *fault = words;
      return NULL;
    }
  }
  if (i == length) return NULL;
  if (i == 0) {
    *fault = "empty length";
    return NULL;
  }
  if (length - (i + 1) < len + 1) return NULL;
  if (p[i + 1 + len] != ',') {
    *fault = "missing comma after payload";
    return NULL;
  }
  *start = i + 1;
  *size = len;
  return p + i + 2 + len;
}

/* Reads once what descriptor fd holds, without waiting, after what its
 * buffer kept. */
static int fill_inbox (struct inbox *box, int fd) {
  unsigned char *grown;
  ssize_t got;
  if (box->size - box->length < POLLER_READ) {
    grown = realloc(box->bytes, box->length + POLLER_READ);
    if (!grown) return -1;
    box->bytes = grown;
    box->size = box->length + POLLER_READ;
  }
  got = recv(fd, box->bytes + box->length, box->size - box->length,
             MSG_DONTWAIT);
  if (got > 0) box->length += got;
  if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR))
    return 1;
  return got > 0;
}

/* (poller-frames! fd max): reads what fd holds and answers the payloads,
 * as bytevectors, of the netstrings now whole, in order; the list ends in
 * an eof object when the peer has closed between frames, or in a string
 * saying what is wrong with the next frame.  What is left of a frame
 * waits in fd's buffer for the rest. */
static sexp poller_frames (sexp ctx, sexp self, sexp_sint_t n, sexp fd,
                           sexp max) {
  struct inbox *box;
  const unsigned char *p, *next;
  const char *fault = NULL;
  size_t start, size, left;
  int open;
  sexp_gc_var3(ls, tail, item);
  if (!sexp_fixnump(fd) || !sexp_fixnump(max))
    return sexp_type_exception(ctx, self, SEXP_FIXNUM,
                               sexp_fixnump(fd) ? max : fd);
  box = inbox_of(sexp_unbox_fixnum(fd));
  if (!box) return sexp_user_exception(ctx, self, "out of memory", fd);
  open = fill_inbox(box, sexp_unbox_fixnum(fd));
  sexp_gc_preserve3(ctx, ls, tail, item);
  ls = tail = SEXP_NULL;
  p = box->bytes;
  left = box->length;
  for (;;) {
    next = next_netstring(p, left, sexp_unbox_fixnum(max), &start, &size,
                          &fault);
    if (!next) {
      if (fault)
        item = sexp_c_string(ctx, fault, -1);
      else if (open)
        break;
      else if (left == 0)
        item = SEXP_EOF;
      else
        item = sexp_c_string(ctx, left && memchr(p, ':', left)
                             ? "truncated payload" : "truncated length", -1);
    } else {
      item = sexp_make_bytes(ctx, sexp_make_fixnum(size), SEXP_ZERO);
      if (!sexp_exceptionp(item))
        memcpy(sexp_bytes_data(item), p + start, size);
    }
    if (sexp_exceptionp(item)) { ls = item; break; }
    item = sexp_cons(ctx, item, SEXP_NULL);
    if (sexp_pairp(tail)) sexp_cdr(tail) = item; else ls = item;
    tail = item;
    if (!next) break;
    left -= next - p;
    p = next;
  }
  if (box->bytes && p != box->bytes) memmove(box->bytes, p, left);
  box->length = left;
  sexp_gc_release3(ctx);
  return ls;
}

sexp sexp_init_library (sexp ctx, sexp self, sexp_sint_t n, sexp env,
                        const char *version, const sexp_abi_identifier_t abi) {
  if (!(sexp_version_compatible(ctx, version, sexp_version)
        && sexp_abi_compatible(ctx, abi, SEXP_ABI_IDENTIFIER)))
    return SEXP_ABI_ERROR;
  sexp_define_foreign(ctx, env, "poll-scheduler-installed?", 0,
                      poll_scheduler_installedp);
  sexp_define_foreign(ctx, env, "others-runnable?", 0, others_runnablep);
  sexp_define_foreign(ctx, env, "cpu-contended?", 0, cpu_contendedp);
  sexp_define_foreign(ctx, env, "monotonic-seconds", 0, monotonic_seconds);
  sexp_define_foreign(ctx, env, "wall-microseconds", 0, wall_microseconds);
  sexp_define_foreign(ctx, env, "stack-guard-tripped?", 1, stack_guard_trippedp);
  sexp_define_foreign(ctx, env, "%port-wait!", 2, port_wait);
  sexp_define_foreign(ctx, env, "poller-port", 0, poller_port);
  sexp_define_foreign(ctx, env, "poller-watch!", 1, poller_watch);
  sexp_define_foreign(ctx, env, "poller-unwatch!", 1, poller_unwatch);
  sexp_define_foreign(ctx, env, "poller-release!", 1, poller_release);
  sexp_define_foreign(ctx, env, "poller-buffered", 1, poller_buffered);
  sexp_define_foreign(ctx, env, "poller-ready", 0, poller_ready);
  sexp_define_foreign(ctx, env, "poller-frames!", 2, poller_frames);
  return install(ctx);
}
