;;;; One-line log messages on standard error.
;;
;; (chibi log) would do, but loading it costs an address space 0.7 s of
;; start-up, and labs start many address spaces.

(define *log-name* "murdoch")

;;> Names this process in log lines, e.g. "murdoch troy".
(define (set-log-name! name) (set! *log-name* name))

(define (log-line level parts)
  (let ((err (current-error-port)))
    (write-string *log-name* err)
    (write-string level err)
    (for-each (lambda (p) (if (string? p) (write-string p err) (display p err)))
              parts)
    (newline err)
    (flush-output-port err)))

;;> Logs something worth knowing.
(define (log-note . parts) (log-line ": " parts))

;;> Logs a fault that was handled.
(define (log-warn . parts) (log-line ": warning: " parts))
