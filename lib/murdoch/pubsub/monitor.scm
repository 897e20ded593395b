;;;; Monitors (thesis A.6) and each address space's first subscriptions
;;;; (A.2): capabilities that come and go with the machine's state.

;; The node's monitors part: the thesis's three thresholds (A.5, A.6),
;; globals there, taken from the lab's settings and changed by their
;; setters; the load's source and its last text.
(define-record-type monitors
  (make-monitors battery-charging battery-low load-threshold load-source last-load)
  monitors?
  (battery-charging monitors-battery-charging monitors-battery-charging-set!)
  (battery-low monitors-battery-low monitors-battery-low-set!)
  (load-threshold monitors-load-threshold monitors-load-threshold-set!)
  (load-source monitors-load-source)    ; a thunk answering a number
  (last-load monitors-last-load monitors-last-load-set!)) ; (LOAD . TEXT)

(define (the-monitors)
  (or (node-monitors (this-node))
      (error "this address space has not started its monitors")))

;;> The thesis's *battery-charging*: the voltage, in tenths, above which a
;;> robot is taken to be on its charging tether.
(define (battery-charging) (monitors-battery-charging (the-monitors)))

;;> The thesis's *battery-low*: the voltage, in tenths, below which a
;;> robot's battery is low.
(define (battery-low) (monitors-battery-low (the-monitors)))

;;> The thesis's *load-threshold*: the load, a string such as ".75" (as the
;;> thesis sent it between machines), below which the load monitor
;;> subscribes to idle.
(define (load-threshold) (monitors-load-threshold (the-monitors)))

;;> Sets (battery-charging), in tenths of a volt.
(define (set-battery-charging! tenths)
  (monitors-battery-charging-set! (the-monitors) tenths))

;;> Sets (battery-low), in tenths of a volt.
(define (set-battery-low! tenths) (monitors-battery-low-set! (the-monitors) tenths))

;;> Sets (load-threshold), a string such as ".75".
(define (set-load-threshold! load) (monitors-load-threshold-set! (the-monitors) load))

;;> This machine's load as a string, e.g. "0.42": from the lab's (load ...)
;;> clause, else the one-minute average of /proc/loadavg.
(define (get-system-load)
  (string-copy (load-text ((monitors-load-source (the-monitors))))))

;; The text of load, kept while it stays (docs/speed.md), copied out for received code.
(define (load-text load)
  (let ((last (monitors-last-load (the-monitors))))
    (if (eqv? load (car last))
        (cdr last)
        (let ((text (number->string load)))
          (monitors-last-load-set! (the-monitors) (cons load text))
          text))))

(define (start-thread! name thunk)
  (thread-start! (make-logged-thread thunk name)))

;; The thesis's names (A.6), global as there: a restarted monitor ends the old thread.
(define *load-monitor-thread* #f)
(define *battery-monitor-thread* #f)

;; Keeps subject subscribed while present? holds, every monitor-period.
(define (watch subject present?)
  (lambda ()
    (let loop ()
      (if (present?) (subscribe subject) (unsubscribe subject))
      (thread-sleep! (setting 'monitor-period))
      (loop))))

;; Starts a monitor thread, terminating the one it replaces, as A.6 does.
(define (restart-monitor! old name thunk)
  (if (thread? old)
      (begin (log-warn "terminating the running " name " thread")
             (thread-terminate! old)))
  (start-thread! name thunk))

(define load-monitor-procedure
  (watch 'idle
         (lambda ()
           (< (string->number (get-system-load))
              (string->number (load-threshold))))))

(define battery-monitor-procedure
  (watch 'untethered
         (lambda () (< (safe-battery-voltage) (battery-charging)))))

;;> Subscribes to idle while the load is under (load-threshold).
(define (load-monitor)
  (set! *load-monitor-thread*
        (restart-monitor! *load-monitor-thread* 'load-monitor
                          load-monitor-procedure))
  #t)

;;> Subscribes to untethered while the battery is under (battery-charging).
(define (battery-monitor)
  (set! *battery-monitor-thread*
        (restart-monitor! *battery-monitor-thread* 'battery-monitor
                          battery-monitor-procedure))
  #t)

;;; Initialization (A.2), from the lab file rather than host names

;; The lab's (load L) or (load ((SECONDS L) ...)), else /proc/loadavg.
(define (load-source clause)
  (let ((start (monotonic-seconds)))
    (cond
     ((not clause) (loadavg-reader))
     ((number? (cadr clause)) (lambda () (cadr clause)))
     (else
      (let ((steps (cadr clause)))
        (lambda ()
          (let ((now (- (monotonic-seconds) start)))
            (fold (lambda (step load) (if (>= now (car step)) (cadr step) load))
                  (cadr (car steps))
                  steps))))))))

(define (read-loadavg)
  (call-with-input-file "/proc/loadavg"
    (lambda (in) (read in))))

;; read-loadavg at most once a second: the kernel updates it every five.
(define (loadavg-reader)
  (let ((read-at #f) (load #f))
    (lambda ()
      (let ((now (monotonic-seconds)))
        (when (or (not read-at) (> now (+ read-at 1)))
          (set! load (read-loadavg))
          (set! read-at now))
        load))))

;;> Sets up this address space's subscriptions and monitors from its lab
;;> clause (the thesis's make-subscription-initializer): all, its uid, its
;;> capabilities, coordinator on a workstation, idle and untethered.
;;> \var{on-free} runs, outside any lock, when exclusive subjects are freed.
(define (initialize-subscriptions! entry)
  (node-monitors-set!
   (this-node)
   (make-monitors (setting 'battery-charging) (setting 'battery-low)
                  (setting 'load-threshold)
                  (load-source (and entry (lab-aspace-clause entry 'load)))
                  (cons #f "")))
  (for-each subscribe (list 'all (local-aspace-uid)))
  (for-each subscribe
            (cond ((and entry (lab-aspace-clause entry 'capabilities)) => cdr)
                  (else '())))
  ;; A workstation may coordinate the tasks handed to the lab (task/detached.scm).
  (if (and entry (lab-aspace-clause entry 'position)) (subscribe 'coordinator))
  (load-monitor)
  (if (and entry (lab-aspace-clause entry 'robot)) (battery-monitor))
  (start-leases!)
  #t)
