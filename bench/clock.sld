;;> The benches' clock of their own CPU: what one process spends, user
;;> and system, by getrusage.

(define-library (bench clock)
  (export own-cpu-us)
  (import (scheme base)
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
      (+ (* 1000000. (timeval-seconds tv)) (timeval-microseconds tv)))))
