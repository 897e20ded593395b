;;; make bench-chaos: tasks that survive failure, under random kills.
;;;
;;; Three posers (threads of this address space, each starting one
;;; restartable one-component task after another) and five robots
;;; (workstations with the mobile capability), while a killer kill -9s a
;;; random robot's address space every few seconds and starts it again a
;;; second later.  Each component tells quiet when it starts and ends on
;;; its robot, so that two exclusive components on one robot at once (a
;;; double booking) are seen from inside.  It prints
;;;   bench: recovery-p50 / -p95 S s   kill to the component running elsewhere
;;;   bench: recovery-floor S s        the same, for a kill whose
;;;                                    connection reset is the only news:
;;;                                    renegotiating one component, measured
;;;                                    here with no kill
;;;   bench: chaos-tasks N, with how they ended
;;;   bench: chaos-double-bookings N, chaos-leaked N, chaos-hung N
;;; Beside them, two more posers hand restartable tasks to the lab
;;; ('detach #t), every other one a task of two steps, coordinated by
;;; three workstations k1..k3, and a second
;;; killer kill -9s a running detached task's coordinator or standby every
;;; few seconds, starting it again a second later.  It prints
;;;   bench: takeover-p50 / -p95 S s   a coordinator's kill to its standby
;;;                                    taking over, by the standby's clock
;;;   bench: takeover-floor S s        what the rule leaves at least: a
;;;                                    heartbeat period, and the lab asked
;;;                                    where the task's components run
;;;   bench: detached-lost N           tasks whose result no peer could read
;;;   bench: detached-double-runs N    a component running twice at once
;;; and tells each failed detached task, and each component begun again
;;; after it completed; a task lost or a component run twice keeps the
;;; lab's logs, and says where.
;;; MURDOCH_CHAOS_SECONDS sets how long the kills go on (default 90).
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (scheme process-context) (scheme inexact) (scheme time)
        (srfi 1) (srfi 18) (srfi 27) (srfi 132)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness)
        (only (murdoch sys scheduler) monotonic-seconds) (only (murdoch lab) setting)
        (only (murdoch wire) error-message) (only (murdoch sys) utc-seconds))

(define seconds
  (cond ((get-environment-variable "MURDOCH_CHAOS_SECONDS") => string->number)
        (else 90)))

(define robots '(r1 r2 r3 r4 r5))
(define workstations '(k1 k2 k3))

(define lab-code "
;; On quiet, each call runs in a thread of its own, and Chibi may switch
;; threads in the middle of a set! of inside: a leave! lost so leaves its
;; robot counted busy, and the robot's next component counted a double
;; booking.  Each reading and change of inside is made under its lock,
;; and of copies under its own, held while copy-enter! asks robots.
(define inside-lock (make-mutex 'inside))
(define copies-lock (make-mutex 'copies))
(define (under lock thunk)
  (mutex-lock! lock)
  (let ((v (thunk))) (mutex-unlock! lock) v))
(define inside '())       ; on quiet: ((uid started-at) . n) now running
(define double-bookings 0)
(define (enter! who)
  (under inside-lock
   (lambda ()
     (let ((e (assoc who inside)))
       (if (and e (> (cdr e) 0)) (set! double-bookings (+ double-bookings 1)))
       (set! inside (cons (cons who (+ 1 (if e (cdr e) 0)))
                          (remove (lambda (x) (equal? (car x) who)) inside)))))))
(define (leave! who)
  (under inside-lock
   (lambda ()
     (set! inside (map (lambda (x) (if (equal? (car x) who) (cons who (- (cdr x) 1)) x))
                       inside)))))
(define (chaos-component)
  (let ((who (list (local-aspace-uid) (aspace-started-at))))
    (remote-apply (uid->aspace 'quiet) (lambda () (enter! who)))
    (dynamic-wind
     (lambda () #f)
     (lambda ()
       (let loop ((n 40))
         (remote-apply (uid->aspace 'quiet) (lambda () #t))
         (thread-sleep! 0.05)
         (if (> n 0) (loop (- n 1)) (local-aspace-uid))))
     (lambda () (tell-quiet (lambda () (leave! who)))))))
;; Applies thunk on quiet from a thread of its own: a component stopped
;; by its poser (cancelled, an orphan, its robot declared lost) has its
;; thread marked abandoned, and a remote call there raises at once, so
;; that its leave! would never arrive and the robot's next component
;; would be counted as a double booking.
(define (tell-quiet thunk)
  (thread-join!
   (thread-start!
    (make-thread (lambda ()
                   (guard (e (#t #f)) (remote-apply (uid->aspace 'quiet) thunk)))))))
;; The copies of each detached task's component running now: (TAG UID
;; STARTED-AT), UID's address space as it was when the copy began.  A copy
;; whose robot was killed never leaves: a copy that begins finds it stale
;; when its robot is away or was started again since.
(define copies '())
(define double-runs 0)
;; The tags of the components that completed, and how many began again
;; after: a step of a task of steps run again after a takeover, say.
(define completed '())
(define reruns 0)
(define (copy-enter! tag who)
  (under copies-lock
   (lambda ()
     (let ((others (filter (lambda (c) (and (equal? (car c) tag) (live-copy? c)))
                           copies)))
       (if (pair? others) (set! double-runs (+ double-runs 1)))
       (if (member tag completed) (set! reruns (+ reruns 1)))
       (set! copies (cons (cons tag who) copies))))))
(define (copy-completed! tag)
  (under copies-lock (lambda () (set! completed (cons tag completed)))))
(define (live-copy? c)
  (guard (e (#t #f))
    (equal? (caddr c)
            (parameterize ((remote-timeout 1))
              (remote-apply (uid->aspace (cadr c)) aspace-started-at)))))
(define (copy-leave! tag who)
  (under copies-lock
   (lambda () (set! copies (remove (lambda (c) (equal? c (cons tag who))) copies)))))
(define (detached-component tag)
  (let ((who (list (local-aspace-uid) (aspace-started-at))))
    (remote-apply (uid->aspace 'quiet) (lambda () (copy-enter! tag who)))
    (dynamic-wind
     (lambda () #f)
     (lambda ()
       (let ((result (chaos-component)))
         (tell-quiet (lambda () (copy-completed! tag)))
         result))
     (lambda () (tell-quiet (lambda () (copy-leave! tag who)))))))
(define (held subjects)
  (apply + (map (lambda (r) (length (filter (lambda (s) (pair? (cadr s))) (cadr r))))
                (request 'all (lambda ()
                                (filter-map (lambda (t)
                                              (let ((s (topic-status t)))
                                                (and s (list t s))))
                                            subjects))))))
")

(define lab
  (make-test-lab
   `((code "code.scm") (lease 10)
     (aspace tester)
     (aspace quiet (load 0.1))
     ,@(map (lambda (uid) `(aspace ,uid (position 0 5000 0) (load 0.1))) workstations)
     ,@(map (lambda (uid i) `(aspace ,uid (position ,(* 1000 i) 0 0)
                                     (capabilities mobile) (load 0.5)))
            robots (iota (length robots))))
   `(("code.scm" . ,lab-code))))

(define pids (map (lambda (uid) (cons uid (start-lab-aspace! lab uid)))
                  (cons 'quiet (append workstations robots))))
(join-lab (test-lab-file lab) 'tester)
(define (lab-proc name) (eval name (lab-environment)))
(define (at-quiet expr)
  (remote-apply (uid->aspace 'quiet) (eval `(lambda () ,expr) (lab-environment))))

;;; The killer

(define kills '())                      ; (uid . monotonic-seconds), newest first, any killer's
(define lock (make-mutex))
(define (locked thunk) (mutex-lock! lock) (let ((v (thunk))) (mutex-unlock! lock) v))

(define (killer until)
  (when (< (monotonic-seconds) until)
    (thread-sleep! (+ 2 (* 2 (random-real))))
    (kill-and-restart! (list-ref robots (random-integer (length robots))))
    (killer until)))

(define (kill-and-restart! uid)
  (locked (lambda () (set! kills (cons (cons uid (monotonic-seconds)) kills))))
  (kill-process! (locked (lambda () (cdr (assq uid pids)))))
  (thread-sleep! 1)
  (let ((pid (start-lab-aspace! lab uid)))
    (locked (lambda () (set! pids (cons (cons uid pid) pids))))))

;; Every few seconds, the coordinator or the standby of a running
;; detached task, in turn, is killed and started again; a coordinator's
;; kill is timed to its standby's takeover.
(define takeovers '())
(define coordinator-kills 0)
(define standby-kills 0)

(define (coordinator-killer until coordinator?)
  (when (< (monotonic-seconds) until)
    (thread-sleep! (+ 2 (* 2 (random-real))))
    (let ((e (find (lambda (e) (and (eq? (lab-task-state e) 'running)
                                    (lab-task-standby e)
                                    (memq (lab-task-coordinator e) workstations)
                                    (memq (lab-task-standby e) workstations)))
                   (lab-tasks))))
      (when e
        (let ((uid (if coordinator? (lab-task-coordinator e) (lab-task-standby e)))
              (killed-at (utc-seconds)))
          (if coordinator?
              (locked (lambda () (set! coordinator-kills (+ coordinator-kills 1))))
              (locked (lambda () (set! standby-kills (+ standby-kills 1)))))
          (kill-and-restart! uid)
          (if coordinator?
              (thread-start!
               (make-thread (lambda () (time-takeover! (lab-task-id e)
                                                       (lab-task-epoch e)
                                                       killed-at))))))))
    (coordinator-killer until (not coordinator?))))

(define (time-takeover! id epoch killed-at)
  (let ((e (wait-until 15 (lambda ()
                            (find (lambda (e) (and (eq? (lab-task-id e) id)
                                                   (> (lab-task-epoch e) epoch)
                                                   (lab-task-took-over e)))
                                  (lab-tasks))))))
    (if e
        (locked (lambda ()
                  (set! takeovers (cons (- (lab-task-took-over e) killed-at)
                                        takeovers)))))))

;; When uid was last killed, at or after moment, or #f.
(define (killed-after uid moment)
  (locked (lambda ()
            (let ((k (find (lambda (k) (and (eq? (car k) uid) (>= (cdr k) moment)))
                           kills)))
              (and k (cdr k))))))

;;; The posers

(define recoveries '())
(define outcomes '())                   ; one symbol a task
(define hung 0)

(define (note! what) (locked (lambda () (set! outcomes (cons what outcomes)))))

;; Starts a task and watches it: each move to another robot after a kill
;; is a recovery, from the kill to the component's start there.
(define (one-task)
  (let ((t (start-task 'chaos 1 (list '((mobile) ())) (list #f)
                       (list (lab-proc 'chaos-component)) '(1) '(#t)))
        (began (monotonic-seconds)))
    (let watch ((uid #f) (since began))
      (let ((state (status-state (car (task-status t)))))
        (cond
         ((memq (car state) '(done failed))
          (note! (outcome-of state)))
         ((> (monotonic-seconds) (+ began 60))
          (locked (lambda () (set! hung (+ hung 1))))
          (cancel-task t))
         ((and (eq? (car state) 'running) (not (eq? (cadr state) uid)))
          (let ((killed (and uid (killed-after uid since))))
            (if killed
                (locked (lambda ()
                          (set! recoveries
                                (cons (- (monotonic-seconds) killed) recoveries))))))
          (thread-sleep! 0.02)
          (watch (cadr state) (monotonic-seconds)))
         (else (thread-sleep! 0.02) (watch uid since)))))))

(define (outcome-of state)
  (cond ((eq? (car state) 'done) 'done)
        ((equal? state '(failed not-enough-takers)) 'not-enough-takers)
        ((and (string? (cadr state))
              (string-search "no other capable robot" (cadr state)))
         'lost-no-robot)
        (else 'failed)))

(define (string-search needle hay)
  (let ((n (string-length needle)) (h (string-length hay)))
    (let loop ((i 0))
      (cond ((> (+ i n) h) #f)
            ((string=? needle (substring hay i (+ i n))) i)
            (else (loop (+ i 1)))))))

(define (poser until)
  (when (< (monotonic-seconds) until)
    (one-task)
    (poser until)))

;;; The detached posers: each hands a task to the lab, then waits for it
;;; by its id, as any peer could.

(define detached-outcomes '())          ; done, failed or lost, one a task
(define tags 0)

(define steps-tasks 0)

;; A task of one component, or every other one of two steps, each of one;
;; each component a copy of its own, (N) or (N STEP).
(define (one-detached-task)
  (let* ((tag (locked (lambda () (set! tags (+ tags 1)) tags)))
         (began (monotonic-seconds))
         (steps? (even? tag))
         (id (if steps?
                 (apply start-steps 'handed-steps
                        (append (map (lambda (i) (detached-step (list tag i))) '(1 2))
                                '(detach #t)))
                 (start-task 'handed 1 (list '((mobile) ())) (list #f)
                             (list (eval `(lambda () (detached-component '(,tag)))
                                         (lab-environment)))
                             '(1) '(#t) 'detach #t)))
         (outcome (guard (e (#t (display (error-message e)) (newline) (tell-holders id) 'lost))
                    (let ((r (task-wait id 60)))
                      (cond ((symbol? r) r)
                            ((and steps? (find symbol? r)))  ; a step's not-enough-takers
                            ((if steps? (every done-one? r) (done-one? r)) 'done)
                            (else (tell-failed id (if steps? (apply append r) r) began) 'failed))))))
    (if steps? (locked (lambda () (set! steps-tasks (+ steps-tasks 1)))))
    (locked (lambda () (set! detached-outcomes (cons outcome detached-outcomes))))))

;; For a task the lab's lookup lost: what each member, asked directly and
;; not through the lab-tasks subject, holds of it, at once and a second on,
;; and which members were killed in the ten seconds before.
(define (tell-holders id)
  (let ((ask (eval `(lambda () (filter (lambda (e) (eq? (car e) ',id)) (handed-entries)))
                   (lab-environment)))
        (members (append workstations robots))
        (since (- (monotonic-seconds) 10)))
    (for-each
     (lambda (when)
       (display (string-append "chaos: lost " (symbol->string id) ", " when ", asked directly:"))
       (for-each (lambda (uid)
                   (display " ")
                   (write (cons uid (guard (e (#t (list 'no-answer (error-message e))))
                                      (parameterize ((remote-timeout 2))
                                        (remote-apply (uid->aspace uid) ask))))))
                 members)
       (newline)
       (thread-sleep! 1))
     '("at once" "a second on"))
    (display "chaos: killed in the ten seconds before: ")
    (write (filter (lambda (uid) (killed-after uid since)) members))
    (newline)))

;; Why a detached task posed at began failed, from its components'
;; results: each (error UID WHY), and whether the killer killed UID since.
(define (tell-failed id results began)
  (display (string-append "chaos: detached " (symbol->string id) " failed: "))
  (for-each (lambda (x)
              (when (and (pair? x) (eq? (car x) 'error))
                (write x)
                (display (if (killed-after (cadr x) began) " (its robot killed) "
                             " (its robot not killed) "))))
            results)
  (newline))

(define (detached-step tag)
  (task-step (list '((mobile) ())) (list #f)
             (list (eval `(lambda (previous) (detached-component ',tag)) (lab-environment)))
             '(1) '(#t)))

;; Whether r, a task's results, are a component's: its robot's uid.
(define (done-one? r) (and (pair? r) (memq (car r) robots) #t))

(define (detached-poser until)
  (when (< (monotonic-seconds) until)
    (guard (e (#t (display (error-message e)) (newline) (thread-sleep! 1)))
      (one-detached-task))
    (detached-poser until)))

;;; The floor: a component moved by hand, with nothing killed -- what
;;; renegotiating one component and starting it again costs.

(define (floor-once)
  (let* ((t0 (monotonic-seconds))
         (r (pose-task 'floor 1 (list '((mobile) ())) (list #f)
                       (list (lambda () #t)))))
    (- (monotonic-seconds) t0)))

(define (median xs)
  (let ((s (list-sort < xs)) (n (length xs)))
    (if (zero? n) +nan.0 (list-ref s (quotient n 2)))))
(define (percentile xs p)
  (let ((s (list-sort < xs)) (n (length xs)))
    (if (zero? n) +nan.0 (list-ref s (min (- n 1) (exact (floor (* p n))))))))
(define (seconds-text x) (number->string (/ (round (* 1000 x)) 1000)))

;; The least a takeover takes: the period the rule waits, and a request
;; to the whole lab, as a takeover asks where the task's components run.
(define (takeover-floor-once)
  (let ((t0 (monotonic-seconds)))
    (request 'all (lambda () (components-running)))
    (+ (setting 'heartbeat) (- (monotonic-seconds) t0))))

(let* ((floors (map (lambda (i) (floor-once)) (iota 7)))
       (takeover-floors (map (lambda (i) (takeover-floor-once)) (iota 7)))
       (until (+ (monotonic-seconds) seconds))
       (threads (append
                 (list (make-thread (lambda () (killer until)))
                       (make-thread (lambda () (coordinator-killer until #t))))
                 (map (lambda (i) (make-thread (lambda () (poser until)))) (iota 3))
                 (map (lambda (i) (make-thread (lambda () (detached-poser until))))
                      (iota 2)))))
  (for-each thread-start! threads)
  (for-each thread-join! threads)
  (wait-until 15 (lambda () (zero? ((lab-proc 'held) '(mobile)))))
  (let ((leaked ((lab-proc 'held) '(mobile)))
        (doubles (at-quiet 'double-bookings)))
    (for-each
     (lambda (line) (display line) (newline))
     (list (string-append "bench: recovery-p50 " (seconds-text (median recoveries)) " s")
           (string-append "bench: recovery-p95 "
                          (seconds-text (percentile recoveries 0.95)) " s")
           (string-append "bench: recovery-floor " (seconds-text (median floors)) " s")
           (string-append "bench: chaos-recoveries " (number->string (length recoveries)))
           (string-append "bench: chaos-tasks " (number->string (length outcomes)))
           (string-append "chaos: kills " (number->string (length kills))
                          "; tasks ended "
                          (let ((kinds '(done lost-no-robot not-enough-takers failed)))
                            (apply string-append
                                   (map (lambda (k)
                                          (string-append
                                           (symbol->string k) " "
                                           (number->string (count (lambda (o) (eq? o k))
                                                                  outcomes))
                                           " "))
                                        kinds))))
           (string-append "bench: chaos-double-bookings " (number->string doubles))
           (string-append "bench: chaos-leaked " (number->string leaked))
           (string-append "bench: chaos-hung " (number->string hung))
           (string-append "bench: takeover-p50 " (seconds-text (median takeovers)) " s")
           (string-append "bench: takeover-p95 "
                          (seconds-text (percentile takeovers 0.95)) " s")
           (string-append "bench: takeover-floor " (seconds-text (median takeover-floors))
                          " s")
           (string-append "chaos: detached tasks " (number->string (length detached-outcomes))
                          " (" (number->string steps-tasks) " of two steps)"
                          ": done " (number->string (count (lambda (o) (eq? o 'done))
                                                           detached-outcomes))
                          ", not-enough-takers "
                          (number->string (count (lambda (o) (eq? o 'not-enough-takers))
                                                 detached-outcomes))
                          ", failed " (number->string (count (lambda (o) (eq? o 'failed))
                                                             detached-outcomes))
                          "; coordinators killed " (number->string coordinator-kills)
                          ", standbys killed " (number->string standby-kills)
                          ", takeovers timed " (number->string (length takeovers)))
           (string-append "bench: detached-lost "
                          (number->string (count (lambda (o) (eq? o 'lost))
                                                 detached-outcomes)))
           (string-append "bench: detached-double-runs "
                          (number->string (at-quiet 'double-runs)))
           (string-append "chaos: detached components begun again after they completed "
                          (number->string (at-quiet 'reruns))
                          " (a robot killed before its result was read, or a step run"
                          " again)")))))

;; A detached task lost, or a component run twice, keeps the lab's logs.
(define keep-logs?
  (or (memq 'lost detached-outcomes)
      (positive? (+ (at-quiet 'double-runs) (at-quiet 'reruns)))))
(stop-all-processes!)
(if keep-logs?
    (begin (display (string-append "chaos: the lab's logs are kept in "
                                   (test-lab-directory lab)))
           (newline))
    (remove-test-lab! lab))
