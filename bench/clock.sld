;;> The benches' clocks of CPU: what one process spends, user and system,
;;> by getrusage, and what another has spent, by its scheduler's count.

(define-library (bench clock)
  (export own-cpu-us process-cpu-us processes-cpu-us)
  (import (scheme base) (scheme file) (scheme read)
          (only (chibi time) get-resource-usage resource-usage/self
                resource-usage-time resource-usage-system-time
                timeval-seconds timeval-microseconds))
  (begin
    ;;> Microseconds of CPU this process has used so far.
    (define (own-cpu-us)
      (let ((r (get-resource-usage resource-usage/self)))
        (+ (timeval-us (resource-usage-time r))
           (timeval-us (resource-usage-system-time r)))))

    (define (timeval-us tv)
      (+ (* 1000000. (timeval-seconds tv)) (timeval-microseconds tv)))

    ;;> Microseconds of CPU that process \var{pid} has used so far: the
    ;;> first field of Linux's /proc/PID/schedstat, in nanoseconds, exact
    ;;> where /proc/PID/stat counts ticks of 10 ms.  Its main thread's,
    ;;> which is all of a Chibi process's: its threads are green.
    (define (process-cpu-us pid)
      (/ (call-with-input-file
             (string-append "/proc/" (number->string pid) "/schedstat")
           read)
         1000.))

    ;;> The sum of process-cpu-us over \var{pids}.
    (define (processes-cpu-us pids)
      (let sum ((pids pids) (us 0.))
        (if (null? pids)
            us
            (sum (cdr pids) (+ us (process-cpu-us (car pids)))))))))
