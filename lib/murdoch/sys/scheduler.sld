;;> Takes the 10 ms nap out of Chibi's green-thread scheduler.
;;>
;;> Importing this library is enough: from then on, whenever every
;;> thread of the process is blocked, the process sleeps in
;;> \scheme{ppoll} on the descriptors the threads wait on, until the
;;> nearest thread's deadline, instead of napping 10 ms at a time.
;;> Threads, mutexes and condition variables of (srfi 18) behave as
;;> before.  The library's body is lib/murdoch/sys/scheduler.c, built into
;;> lib/murdoch/sys/scheduler.so by \scheme{make native}.
;;>
;;> \procedure{(poll-scheduler-installed?)}
;;> Returns \scheme{#t} once the wrapper is in place, which importing
;;> the library does.
;;>
;;> \procedure{(stack-guard-tripped? thread)}
;;> Whether \var{thread} was interrupted because its stack neared
;;> Chibi's limit (which would end the process); answers so once.
;;>
;;> \procedure{(monotonic-seconds)}
;;> Seconds since a fixed moment, as a flonum, from a clock that only goes
;;> forward: for deadlines.  (scheme time)'s \scheme{current-second} costs
;;> some microseconds a call and jumps when the wall clock is set.
;;>
;;> \procedure{(wall-microseconds)}
;;> Microseconds since 1970 by the system's real-time clock, as an exact
;;> integer: a moment that other hosts can compare, read in a tenth of
;;> a microsecond where \scheme{current-second} takes two.
;;>
;;> \procedure{(port-wait! port seconds)}
;;> Pauses the calling thread, and only it, until \var{port}'s descriptor
;;> is ready (to read, for an input port; to write, for an output port)
;;> or \var{seconds} have passed, whichever is first.  The caller then
;;> looks again at what it waits for: readiness is a hint.
;;>
;;> \procedure{(poller-port)}
;;> An input port on the process's one epoll descriptor, made at the first
;;> call: it is ready when a watched descriptor is.  Only one thread, the
;;> poller's, waits on it, with port-wait!.
;;>
;;> \procedure{(poller-watch! port)}
;;> Watches the descriptor of the input port \var{port}, with an empty
;;> buffer of its own; answers the descriptor.
;;>
;;> \procedure{(poller-unwatch! fd)}
;;> Stops watching \var{fd} and drops its buffer; call it before the
;;> descriptor is closed.
;;>
;;> \procedure{(poller-release! fd)}
;;> Stops watching \var{fd} but keeps its buffer, for a thread of its own
;;> to read on with poller-frames!; poller-unwatch! drops it at the end.
;;>
;;> \procedure{(poller-buffered fd)}
;;> How many bytes of a frame not yet whole \var{fd}'s buffer holds.
;;>
;;> \procedure{(poller-ready)}
;;> The watched descriptors with bytes to read or an end, without waiting.
;;>
;;> \procedure{(poller-frames! fd max)}
;;> Reads once what \var{fd} holds, without waiting, and answers the
;;> payloads of the netstrings now whole, in order, as bytevectors; the
;;> list ends in an eof object when the peer closed between frames, or in a
;;> string saying what is wrong with the next frame (as read-netstring's
;;> errors say it).  Part of a frame waits in the buffer for the rest.

(define-library (murdoch sys scheduler)
  (export poll-scheduler-installed? monotonic-seconds wall-microseconds
          stack-guard-tripped?
          port-wait!
          poller-port poller-watch! poller-unwatch! poller-release!
          poller-buffered poller-ready poller-frames!)
  ;; (srfi 18) installs Chibi's scheduler, which the wrapper goes in front of.
  (import (scheme base) (srfi 18))
  (include-shared "scheduler")
  (begin
    (define (port-wait! port seconds)
      (%port-wait! port (inexact seconds))
      (thread-yield!))))
