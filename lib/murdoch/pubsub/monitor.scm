;;;; Monitors (thesis A.6) and each address space's first subscriptions
;;;; (A.2): capabilities that come and go with the machine's state.

;; The thesis's names (A.5, A.6), global as there; received code cannot
;; assign them (code/sandbox.scm) but uses their procedures.
;;> The voltage, in tenths, above which a robot is taken to be on its
;;> charging tether.
(define *battery-charging* (lab-default 'battery-charging))
;;> The voltage, in tenths, below which a robot's battery is low.
(define *battery-low* (lab-default 'battery-low))

;;> The load, a string such as ".75" (as the thesis sent it between
;;> machines), below which the load monitor subscribes to idle.
(define *load-threshold* (lab-default 'load-threshold))

;;> Sets *battery-charging*, in tenths of a volt.
(define (set-battery-charging! tenths) (set! *battery-charging* tenths))

;;> Sets *battery-low*, in tenths of a volt.
(define (set-battery-low! tenths) (set! *battery-low* tenths))

;;> Sets *load-threshold*, a string such as ".75".
(define (set-load-threshold! load) (set! *load-threshold* load))

;; What the monitors take from the lab: monitor-period, and the load's source.
(define-record-type monitoring
  (make-monitoring period load-source last-load)
  monitoring?
  (period monitoring-period)            ; seconds between looks
  (load-source monitoring-load-source)  ; a thunk answering a number
  (last-load monitoring-last-load monitoring-last-load-set!)) ; (LOAD . TEXT)

;; Global: the monitors are the thesis's procedures of no arguments.
(define *monitoring* #f)

;;> This machine's load as a string, e.g. "0.42": from the lab's (load ...)
;;> clause, else the one-minute average of /proc/loadavg.
(define (get-system-load)
  (string-copy (load-text ((monitoring-load-source *monitoring*)))))

;; The text of load, kept while it stays (docs/speed.md), copied out for received code.
(define (load-text load)
  (let ((last (monitoring-last-load *monitoring*)))
    (if (eqv? load (car last))
        (cdr last)
        (let ((text (number->string load)))
          (monitoring-last-load-set! *monitoring* (cons load text))
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
      (thread-sleep! (monitoring-period *monitoring*))
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
              (string->number *load-threshold*)))))

(define battery-monitor-procedure
  (watch 'untethered
         (lambda () (< (safe-battery-voltage) *battery-charging*))))

;;> Subscribes to idle while the load is under *load-threshold*.
(define (load-monitor)
  (set! *load-monitor-thread*
        (restart-monitor! *load-monitor-thread* 'load-monitor
                          load-monitor-procedure))
  #t)

;;> Subscribes to untethered while the battery is under *battery-charging*.
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
(define (initialize-subscriptions! lab entry on-free)
  (on-free! on-free)
  (set! *monitoring*
        (make-monitoring (lab-setting lab 'monitor-period)
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
  (start-leases! lab)
  #t)
