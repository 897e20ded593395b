;;> Takes the 10 ms nap out of Chibi's green-thread scheduler, on import:
;;> with every thread blocked the process sleeps in \scheme{ppoll} until a
;;> descriptor is ready or the nearest deadline.  Body: scheduler.c.
;;> \procedure{(poll-scheduler-installed?)} #t once the wrapper is in place.
;;> \procedure{(stack-guard-tripped? thread)} Whether \var{thread} was stopped near Chibi's stack limit (once).
;;> \procedure{(others-runnable?)} Whether another thread could run now, were this one to yield.
;;> \procedure{(cpu-contended?)} Whether this process waited an eighth of the last 10 ms for a CPU.
;;> \procedure{(monotonic-seconds)} Seconds on a clock that only goes forward.
;;> \procedure{(wall-microseconds)} Microseconds since 1970, for other hosts to compare.
;;> \procedure{(port-wait! port seconds)} Pauses this thread until \var{port} is ready (a hint) or time is up.
;;> \procedure{(poller-port)} An input port on the process's one epoll descriptor.
;;> \procedure{(poller-watch! port)} Watches \var{port}'s descriptor, with a buffer; answers it.
;;> \procedure{(poller-unwatch! fd)} Stops watching \var{fd}, drops its buffer; before closing it.
;;> \procedure{(poller-release! fd)} Stops watching \var{fd}, keeping its buffer for poller-frames!.
;;> \procedure{(poller-buffered fd)} Bytes of an unfinished frame in \var{fd}'s buffer.
;;> \procedure{(poller-ready)} The watched descriptors with bytes or an end.
;;> \procedure{(poller-frames! fd max)} The netstrings now whole on \var{fd}, read without waiting;
;;> last an eof object, or a string saying what is wrong.
;;> eof object when the peer closed, or a string saying what is wrong.
;;> errors say it).  Part of a frame waits in the buffer for the rest.

(define-library (murdoch sys scheduler)
  (export poll-scheduler-installed? others-runnable? cpu-contended? monotonic-seconds wall-microseconds
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
