;;;; One-line log messages on standard error ((chibi log) loads slowly).

;; Global: every thread of the process logs under one name, set at start.
(define *log-name* "murdoch")

;;> Names this process in log lines, e.g. "murdoch troy".
(define (set-log-name! name) (set! *log-name* name))

;; Global: the process writes one log, stamped or not.
(define *stamped?* #f)

;;> Starts each log line with the UTC time to the millisecond.
(define (stamp-log-lines!) (set! *stamped?* #t))

;;> Seconds since 1970 by the system's clock, UTC (current-second is TAI's, 37 ahead).
(define (utc-seconds)
  (let ((tv (car (get-time-of-day))))
    (+ (timeval-seconds tv) (/ (timeval-microseconds tv) 1000000.))))

;; "2026-11-25T03:19:13.123Z " for seconds since 1970 (H. Hinnant's civil dates).
(define (timestamp seconds)
  (let* ((ms (exact (floor (* 1000 seconds))))
         (days (floor-quotient ms 86400000))
         (in-day (floor-remainder ms 86400000))
         (z (+ days 719468))
         (era (floor-quotient z 146097))
         (doe (- z (* era 146097)))
         (yoe (quotient (- doe (quotient doe 1460) (- (quotient doe 36524))
                           (quotient doe 146096))
                        365))
         (doy (- doe (- (+ (* 365 yoe) (quotient yoe 4)) (quotient yoe 100))))
         (mp (quotient (+ (* 5 doy) 2) 153))
         (day (+ 1 (- doy (quotient (+ (* 153 mp) 2) 5))))
         (month (if (< mp 10) (+ mp 3) (- mp 9)))
         (year (+ yoe (* era 400) (if (<= month 2) 1 0))))
    (string-append (digits year 4) "-" (digits month 2) "-" (digits day 2)
                   "T" (digits (quotient in-day 3600000) 2)
                   ":" (digits (quotient (remainder in-day 3600000) 60000) 2)
                   ":" (digits (quotient (remainder in-day 60000) 1000) 2)
                   "." (digits (remainder in-day 1000) 3) "Z ")))

(define (digits n width)
  (let ((s (number->string n)))
    (if (< (string-length s) width)
        (string-append (make-string (- width (string-length s)) #\0) s)
        s)))

;; Written whole by one write-string, lest another thread's line cut in.
(define (log-line level parts)
  (let ((err (current-error-port)))
    (write-string (line-text level parts) err)
    (flush-output-port err)))

(define (line-text level parts)
  (let ((out (open-output-string)))
    (if *stamped?* (write-string (timestamp (utc-seconds)) out))
    (write-string *log-name* out)
    (write-string level out)
    (for-each (lambda (p) (if (string? p) (write-string p out) (display p out)))
              parts)
    (newline out)
    (get-output-string out)))

;;> Logs something worth knowing.
(define (log-note . parts) (log-line ": " parts))

;;> Logs a fault that was handled.
(define (log-warn . parts) (log-line ": warning: " parts))

;;> What \var{e}, any raised object, says, as one line.
(define (condition-message e)
  (cond
   ((stack-guard-tripped? (current-thread))
    "recursed too deep: its stack neared Chibi's limit, which ends a process")
   ((error-object? e)
    (call-with-output-string
      (lambda (out)
        (write-string (error-object-message e) out)
        (for-each (lambda (x)
                    (write-char #\space out)
                    (write (strip-syntactic-closures x) out))
                  (error-object-irritants e)))))
   (else (call-with-output-string
           (lambda (out) (write-string "raised " out) (write e out))))))
