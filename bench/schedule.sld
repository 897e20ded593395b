;;> The scheduling benches' judge (bench/sched.scm, bench/sched-scale.scm):
;;> from the tasks posed, when each was posed, and the starts and ends
;;> their components told, what happened (spans, double bookings, stalls,
;;> inversions, start latencies) and the ideal schedule of the same tasks,
;;> and the figures that compare them.
;;>
;;> A task is (ID KINDS SECONDS PRIORITY GAP): KINDS a list, a component,
;;> of the robot kinds that component accepts; ids are 0 to n-1.  An event
;;> is (TIME KIND ID K UID), KIND start or end of component K of task ID on
;;> robot UID, in time order.  Robots are ((UID . KIND) ...).

(define-library (bench schedule)
  (export bench-lab-code start-bench-lab! lab-proc bench-told seeded-reals below
          make-schedule-run schedule-completed! print-schedule-figures
          schedule-spans schedule-makespan schedule-last-release-latencies percentile round-to bench)
  (import (scheme base) (scheme write) (scheme inexact) (scheme eval) (scheme time)
          (srfi 1) (srfi 27) (srfi 132)
          (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
          (murdoch cli command) (murdoch testing harness))
  (begin
    ;;> The lab code both benches share, before each one's pose-bench!: the
    ;;> bench's clock and the events its components tell it (started counts
    ;;> the tasks whose first component started), and bench-work, a
    ;;> component: a timed wait on its robot, told as it starts and ends.
    (define bench-lab-code "
(define clock #f)
(define events '())                     ; (time kind id k uid), newest first
(define started 0)
;; Under a lock: the robots' calls run in threads of their own, and one
;; between another's reading of events and its set! lost an event (54
;; tasks of 2,500 told fewer starts or ends than they had, on a loaded
;; host).
(define noting (make-mutex 'noting))
(define (noted! thunk)
  (mutex-lock! noting)
  (thunk)
  (mutex-unlock! noting))
(define (note! kind id k uid)
  (noted! (lambda ()
            (if (and (eq? kind 'start) (= k 1)) (set! started (+ started 1)))
            (set! events (cons (list (clock) kind id k uid) events)))))
(define (bench-work id k seconds)
  (let ((me (local-aspace-uid)))
    (remote-apply (uid->aspace 'bench) (lambda () (note! 'start id k me)))
    (dynamic-wind
     (lambda () #f)
     (lambda () (thread-sleep! seconds) me)
     (lambda () (tell-bench (lambda () (note! 'end id k me)))))))
;; From a thread of its own: a component stopped by its poser (an orphan
;; on a loaded host, say) has its thread marked abandoned, where a remote
;; call raises, and its end untold made its robot's next start a double
;; booking to the judge.  Told again until it lands: on a loaded host an
;; end lost to a timeout left its task with no span, and the judge took
;; it for a task waiting for ever, the better-ranked one of 2,495
;; inversions.
(define (tell-bench thunk)
  (thread-join!
   (thread-start!
    (make-thread (lambda ()
                   (let retry ((n 10))
                     (if (and (not (guard (e (#t #f))
                                     (remote-apply (uid->aspace 'bench) thunk)
                                     #t))
                              (> n 0))
                         (retry (- n 1)))))))))

;; Run on the posers: the tasks posed here, (ID . TASK), and a look
;; every 50 ms at what those that hold robots while they wait hold, each
;; change told to the bench, which notes it as (TIME ID UID ...): the
;; judge asks whether a better-ranked task could have used a robot that
;; went elsewhere, which the starts and ends alone do not say.  The ids
;; as ranks name them are made once a task: made every 50 ms, for hundreds
;; of tasks, they were CPU of the poser's that the bench charged the lab.
(define posed '())
(define ids '())                        ; (TASK-ID-STRING . ID)
(define watching #t)
(define (posed! id task)
  (if (null? posed) (thread-start! (make-thread watch-holdings)))
  (set! ids (cons (cons (symbol->string (task-id task)) id) ids))
  (set! posed (cons (cons id task) posed)))
(define (watch-holdings)
  (let loop ((last '()))                ; (ID UID ...) of each task holding
    (let* ((now (filter-map (lambda (e)
                              (let ((id (assoc (list-ref (car e) 2) ids)))
                                (and id (cons (cdr id) (cadr e)))))
                            (waiting-ranks #t)))
           (changes (append (remove (lambda (h) (member h last)) now)
                            (filter-map (lambda (h) (and (not (assv (car h) now)) (list (car h))))
                                        last))))
      (if (pair? changes)
          (tell-bench (lambda () (for-each (lambda (h) (note-holding! h)) changes))))
      (thread-sleep! 0.05)
      (if watching (loop now)))))
(define (bench-results seconds)
  (let ((results (map (lambda (p) (list (car p) (task-wait (cdr p) seconds))) posed)))
    (set! watching #f)
    results))
;; Run on the bench: each change of what a task holds, newest first.
(define holdings '())
(define (note-holding! h)
  (noted! (lambda () (set! holdings (cons (cons (clock) h) holdings)))))
")

    ;;> Starts the address spaces \var{uids} of test lab \var{lab}, joins
    ;;> it as bench, waits up to \var{seconds} for them all to be live, and
    ;;> sets the lab code's clock to this one's: answers their pids.
    (define (start-bench-lab! lab uids seconds)
      (let ((pids (map (lambda (uid) (start-lab-aspace! lab uid)) uids)))
        (join-lab (test-lab-file lab) 'bench)
        (wait-until seconds (lambda () (every (lambda (u) (memq u (live-uids))) uids)))
        (eval (list 'set! 'clock current-second) (lab-environment))
        pids))

    ;;> The lab code's procedure \var{name}, to send to a poser.
    (define (lab-proc name) (eval name (lab-environment)))

    ;;> What the bench was told, the lab code's list \var{name} (events or
    ;;> holdings), oldest first, its seconds from \var{t0} on.
    (define (bench-told name t0)
      (map (lambda (e) (cons (- (car e) t0) (cdr e)))
           (reverse (remote-apply (uid->aspace 'bench)
                                  (eval (list 'lambda '() name) (lab-environment))))))

    ;;> Reals in [0, 1) drawn from \var{seed}, the same in every run.
    (define (seeded-reals seed)
      (let ((source (make-random-source)))
        (random-source-pseudo-randomize! source seed 0)
        (random-source-make-reals source)))

    ;;> An integer below \var{n}, drawn by \var{reals}.
    (define (below reals n) (exact (floor (* n (reals)))))

    (define-record-type schedule-run
      (%make-schedule-run tasks posed-at posed-by events holdings robots aging
                          spans ready starts completed)
      schedule-run?
      (tasks run-tasks)
      (posed-at run-posed-at)           ; vector by id: second before posing
      (posed-by run-posed-by)           ; vector by id: second after
      (events run-events)
      (holdings run-holdings)           ; vector by id: ((TIME UID ...) ...), oldest first
      (robots run-robots)
      (aging run-aging)
      (spans schedule-spans)            ; vector by id: (start end) or #f
      (ready run-ready)                 ; vector by id: last release before start
      (starts run-starts)               ; vector by id: ((time uid k) ...)
      (completed run-completed run-completed-set!))

    (define (task-kinds t) (cadr t))
    (define (task-robots t) (length (task-kinds t)))
    (define (task-priority t) (list-ref t 3))

    ;;> The run's record, its spans and releases computed once;
    ;;> \var{holdings}, (TIME ID UID ...) at each change of what a waiting
    ;;> task holds, oldest first.
    (define (make-schedule-run tasks posed-at posed-by events holdings robots aging)
      (let* ((n (length tasks))
             (spans (make-vector n #f))
             (ready (make-vector n #f))
             (firsts (make-vector n '()))   ; (time uid k) of each start
             (held (make-vector n '()))
             (lasts (make-vector n '()))
             (ends-on '()))                 ; (uid time ...), newest first
        (for-each
         (lambda (e)
           (let ((id (list-ref e 2)) (uid (list-ref e 4)))
             (if (eq? (cadr e) 'start)
                 (vector-set! firsts id (cons (list (car e) uid (list-ref e 3))
                                              (vector-ref firsts id)))
                 (begin
                   (vector-set! lasts id (cons (car e) (vector-ref lasts id)))
                   (set! ends-on (let ((r (assq uid ends-on)))
                                   (if r
                                       (begin (set-cdr! r (cons (car e) (cdr r))) ends-on)
                                       (cons (list uid (car e)) ends-on))))))))
         events)
        (for-each
         (lambda (t)
           (let ((s (vector-ref firsts (car t))) (e (vector-ref lasts (car t))))
             (when (and (= (length s) (task-robots t)) (= (length e) (task-robots t)))
               (let ((start (apply min (map car s))))
                 (vector-set! spans (car t) (list start (apply max e)))
                 ;; The last release among its robots before it started.
                 (let ((releases
                        (filter-map
                         (lambda (x)
                           (let ((before (filter (lambda (end) (<= end start))
                                                 (cond ((assq (cadr x) ends-on) => cdr)
                                                       (else '())))))
                             (and (pair? before) (apply max before))))
                         s)))
                   (if (pair? releases)
                       (vector-set! ready (car t) (apply max releases))))))))
         tasks)
        (for-each (lambda (h)
                    (vector-set! held (cadr h) (cons (cons (car h) (cddr h))
                                                     (vector-ref held (cadr h)))))
                  (reverse holdings))
        (tell-untold! tasks firsts lasts)
        (%make-schedule-run tasks posed-at posed-by events held robots aging spans ready
                            firsts 0)))

    ;; Names on standard error each task whose components did not all
    ;; tell one start and one end: it has no span.
    (define (tell-untold! tasks firsts lasts)
      (for-each (lambda (t)
                  (let ((s (length (vector-ref firsts (car t))))
                        (e (length (vector-ref lasts (car t)))))
                    (if (not (= s e (task-robots t)))
                        (write-string
                         (string-append "sched: task " (number->string (car t)) " told "
                                        (number->string s) " starts and "
                                        (number->string e) " ends of its "
                                        (number->string (task-robots t)) " components\n")
                         (current-error-port)))))
                tasks))

    ;;> Sets how many tasks completed, as their posers said.
    (define (schedule-completed! run n) (run-completed-set! run n))

    (define (span-of run t) (vector-ref (schedule-spans run) (car t)))
    (define (posed run t) (vector-ref (run-posed-at run) (car t)))
    (define (work-of run t)
      (let ((s (span-of run t))) (and s (- (cadr s) (car s)))))

    ;;> When the last component ended.
    (define (schedule-makespan run)
      (fold (lambda (e m) (if (eq? (cadr e) 'end) (max m (car e)) m)) 0 (run-events run)))

    ;; Two components on one robot at once, seen by their starts and ends.
    (define (double-bookings run)
      (let loop ((es (run-events run)) (inside '()) (n 0))
        (if (null? es)
            n
            (let* ((e (car es)) (uid (list-ref e 4))
                   (k (cond ((assq uid inside) => cdr) (else 0)))
                   (rest (remove (lambda (x) (eq? (car x) uid)) inside)))
              (if (eq? (cadr e) 'start)
                  (begin
                    (if (> k 0) (tell-double-booking! run e))
                    (loop (cdr es) (cons (cons uid (+ k 1)) rest) (if (> k 0) (+ n 1) n)))
                  (loop (cdr es) (cons (cons uid (- k 1)) rest) n))))))

    (define (rank-key run t)
      (- (task-priority t) (* (run-aging run) (posed run t))))
    (define (ranks-before? run)
      (lambda (a b)
        (or (> (rank-key run a) (rank-key run b))
            (and (= (rank-key run a) (rank-key run b)) (< (posed run a) (posed run b))))))

    ;; Whether a ranks before b whatever second within its posing call each
    ;; was ranked by: a near tie that the calls' own times could turn either
    ;; way is no inversion.
    (define (surely-ranks-before? run a b)
      (let ((key (lambda (t posed)
                   (- (task-priority t) (* (run-aging run) (vector-ref posed (car t)))))))
        (or (> (key a (run-posed-by run)) (key b (run-posed-at run)))
            (and (= (task-priority a) (task-priority b))
                 (< (vector-ref (run-posed-by run) (car a))
                    (vector-ref (run-posed-at run) (car b)))))))

    ;; The inversions, as issue 43 means them: a freed robot that did not
    ;; go to the best-ranked waiting task that could use it.  For each
    ;; robot a task x started on, the second it got it: when x began to
    ;; hold it, for good, or else its start there (won and started in one
    ;; try).  A task y that surely ranks before x was wronged if it was
    ;; waiting then (posed 0.2 s before, not started 0.2 s after) and, 0.2
    ;; s after, still had a component open that accepts the robot's kind.
    ;; A task that holds keeps each robot for the component it won it for,
    ;; so a robot of a kind only its held components accept is of no use
    ;; to it, and one that went to x while y's need was met within 0.2 s
    ;; (two robots freed together, say) cost y nothing: neither is an
    ;; inversion.  An earlier judge took every task that waited with a
    ;; component accepting the kind as wronged, and a task whose end was
    ;; never told as waiting for ever.  (x y uid) for each x, with the
    ;; best-ranked such y and the robot.
    (define (inversions run)
      (let ((sorted (list-sort (ranks-before? run) (run-tasks run))))
        (filter-map
         (lambda (x)
           (let ((before (take-while (lambda (y) (not (eq? y x))) sorted)))
             (any (lambda (s)
                    (let ((y (wronged run x before (got-at run x s)
                                      (cdr (assq (cadr s) (run-robots run))))))
                      (and y (list x y (cadr s)))))
                  (vector-ref (run-starts run) (car x)))))
         (run-tasks run))))

    ;; The second task x got the robot of its start s, (TIME UID K).
    (define (got-at run x s)
      (let loop ((hs (vector-ref (run-holdings run) (car x))) (since #f))
        (if (or (null? hs) (> (caar hs) (car s)))
            (or since (car s))
            (loop (cdr hs) (and (memq (cadr s) (cdar hs)) (or since (caar hs)))))))

    ;; The best-ranked of ys, each ranked before x, wronged by x's getting
    ;; a robot of kind at second t: it had a component open that accepts
    ;; the kind then and 0.2 s after, and the robot it got for such a
    ;; component was not one free at t already (freed with x's, on its
    ;; way to it), which cost it nothing but its own try's time, measured
    ;; as latency.  Those two excused 56 of 83 in a run on main, 122 of
    ;; 157 in a loaded one (docs/allocation.md).
    (define (wronged run x ys t kind)
      (find (lambda (y)
              (and (surely-ranks-before? run y x)
                   (< (+ (vector-ref (run-posed-by run) (car y)) 0.2) t)
                   (let ((sy (first-start run y)))
                     (or (not sy) (> sy (+ t 0.2))))
                   (open-for? run y t kind)
                   (open-for? run y (+ t 0.2) kind)
                   (not (served-by? run y t kind))))
            ys))

    (define (open-for? run y at kind)
      (any (lambda (accepts) (memq kind accepts)) (open-components run y at)))

    ;; Whether y got, at t or after, for a component accepting kind, a
    ;; robot free from t on: nothing ran on it between t and then.
    (define (served-by? run y t kind)
      (any (lambda (s)
             (let ((got (got-at run y s)))
               (and (>= got t)
                    (memq kind (list-ref (task-kinds y) (- (list-ref s 2) 1)))
                    (let ((e (last-event-on run (cadr s) got)))
                      (or (not e) (and (eq? (cadr e) 'end) (<= (car e) t)))))))
           (vector-ref (run-starts run) (car y))))

    ;; The last event on robot uid before second at, #f if none.
    (define (last-event-on run uid at)
      (let loop ((es (run-events run)) (last #f))
        (if (or (null? es) (>= (caar es) at))
            last
            (loop (cdr es) (if (eq? (list-ref (car es) 4) uid) (car es) last)))))

    ;; When t's first component started, #f if none did.
    (define (first-start run t)
      (let ((s (vector-ref (run-starts run) (car t))))
        (and (pair? s) (apply min (map car s)))))

    ;; The uids t held at second at.
    (define (held-at run t at)
      (let loop ((hs (vector-ref (run-holdings run) (car t))) (held '()))
        (if (or (null? hs) (> (caar hs) at)) held (loop (cdr hs) (cdar hs)))))

    ;; The kinds each component of t that held no robot at second at
    ;; accepts.  A robot held is for the component that later started on
    ;; it, or, given up before, for the first component of its kind left.
    (define (open-components run t at)
      (let* ((held (held-at run t at))
             (ran-on (lambda (k)
                       (let ((s (find (lambda (s) (= (list-ref s 2) k))
                                      (vector-ref (run-starts run) (car t)))))
                         (and s (cadr s)))))
             (open (filter (lambda (k) (not (memq (ran-on k) held)))
                           (iota (task-robots t) 1)))
             (others (remove (lambda (uid) (any (lambda (k) (eq? uid (ran-on k)))
                                                 (iota (task-robots t) 1)))
                             held)))
        (let loop ((others others) (open open))
          (if (null? others)
              (map (lambda (k) (list-ref (task-kinds t) (- k 1))) open)
              (let* ((kind (cdr (assq (car others) (run-robots run))))
                     (k (find (lambda (k) (memq kind (list-ref (task-kinds t) (- k 1))))
                              open)))
                (loop (cdr others) (if k (delete k open) open)))))))

    ;; Each inversion, on standard error, so that a run's can be looked into.
    ;; Names on standard error the start e, (TIME start ID K UID), and
    ;; the last start on its robot before it.
    (define (tell-double-booking! run e)
      (let ((before (find (lambda (b) (and (eq? (cadr b) 'start) (eq? (list-ref b 4) (list-ref e 4))
                                           (< (car b) (car e))))
                          (reverse (run-events run)))))
        (write-string (string-append "sched: double booking: " (event-line e)
                                     "\n  while on it: "
                                     (if before (event-line before) "?") "\n")
                      (current-error-port))))

    (define (event-line e)
      (string-append "component " (number->string (list-ref e 3)) " of task "
                     (number->string (list-ref e 2)) " on "
                     (symbol->string (list-ref e 4)) " at "
                     (number->string (round-to (car e) 3)) " s"))

    (define (tell-inversion! run xyr)
      (let ((x (car xyr)) (y (cadr xyr)))
        (define (task-line t)
          (let ((s (first-start run t)))
            (string-append "task " (number->string (car t)) " of priority "
                           (number->string (task-priority t)) ", posed at "
                           (number->string (round-to (posed run t) 3))
                           " s, started at "
                           (if s (string-append (number->string (round-to s 3)) " s") "never"))))
        (write-string (string-append "sched: inversion: " (task-line x) ", on "
                                     (symbol->string (car (cddr xyr))) "\n"
                                     "  while this better-ranked one waited: "
                                     (task-line y) "\n")
                      (current-error-port))))

    ;; How many tasks were posed before second t, less how many started at
    ;; or before it: how many waited then.
    (define (waiting-counter run)
      (let* ((poses (list->vector (list-sort < (map (lambda (t) (posed run t))
                                                    (run-tasks run)))))
             (starts (list->vector (list-sort < (filter-map (lambda (t) (first-start run t))
                                                            (run-tasks run))))))
        (lambda (t) (- (count-below poses t) (count-below starts (+ t 1e-9))))))

    ;; How many of sorted vector v are below x (then at or above, for
    ;; starts: a task starting at t waits at t).
    (define (count-below v x)
      (let loop ((lo 0) (hi (vector-length v)))
        (if (>= lo hi)
            lo
            (let ((mid (quotient (+ lo hi) 2)))
              (if (< (vector-ref v mid) x) (loop (+ mid 1) hi) (loop lo mid))))))

    ;; (UID START END) of each component that ran.
    (define (runs-on-robots run)
      (let loop ((es (run-events run)) (open '()) (out '()))
        (cond ((null? es) out)
              ((eq? (cadr (car es)) 'start)
               (loop (cdr es) (cons (car es) open) out))
              (else
               (let* ((e (car es))
                      (s (find (lambda (s) (equal? (cddr s) (cddr e))) open)))
                 (loop (cdr es) (if s (delete s open eq?) open)
                       (if s (cons (list (list-ref e 4) (car s) (car e)) out) out)))))))

    ;; The windows of 2 s or more, seen every 0.1 s, in which quiet? holds
    ;; at each second, given the robots running then: the runs are swept
    ;; in order of start, as a run's thousands are too many to look
    ;; through at each step.
    (define (windows run quiet?)
      (let ((makespan (schedule-makespan run)))
        (let loop ((t 0) (runs (list-sort (lambda (a b) (< (cadr a) (cadr b)))
                                          (runs-on-robots run)))
                   (active '()) (quiet 0) (n 0))
          (if (> t makespan)
              n
              (let* ((started (take-while (lambda (r) (<= (cadr r) t)) runs))
                     (active (filter (lambda (r) (< t (car (cddr r)))) (append started active)))
                     (quiet (if (quiet? t (map car active)) (+ quiet 0.1) 0)))
                (loop (+ t 0.1) (drop runs (length started)) active quiet
                      (if (and (>= quiet 2) (< quiet 2.1)) (+ n 1) n)))))))

    ;; Stalls: 2 s or more with a task posed and not started, and no
    ;; component running: the lab idle while tasks wait, a cost of the
    ;; turns, not a deadlock in itself.
    (define (stalls run)
      (let ((waiting-at (waiting-counter run)))
        (windows run (lambda (t running) (and (> (waiting-at t) 0) (null? running))))))

    ;; Deadlocks: 2 s or more of a holding cycle.  The old judge counted
    ;; stalls as deadlocks, but a deadlock is tasks waiting on each other:
    ;; a waiting task y waits on z at second t when y has a component open
    ;; whose every robot is held, none free and none running (a running one
    ;; ends, a free one may be taken), and z holds one of them; a cycle of
    ;; such waits, y waiting on itself included, is a deadlock.
    (define (deadlocks run)
      (let ((holders (filter (lambda (t) (pair? (vector-ref (run-holdings run) (car t))))
                             (run-tasks run))))
        (windows run (lambda (t running) (holding-cycle? run holders t)))))

    (define (holding-cycle? run holders t)
      (let* ((now (filter-map (lambda (y)
                                (let ((hs (vector-ref (run-holdings run) (car y))))
                                  (and (<= (caar hs) t (car (last hs)))
                                       (let ((held (held-at run y t)) (sy (first-start run y)))
                                         (and (pair? held) (or (not sy) (> sy t))
                                              (cons y held))))))
                              holders))
             (held (append-map cdr now))
             (kind-of (lambda (uid) (cdr (assq uid (run-robots run)))))
             (unheld? (lambda (kind)
                          (any (lambda (r) (and (eq? (cdr r) kind) (not (memq (car r) held))))
                               (run-robots run))))
             (waits-on
              (lambda (y)
                (let ((blocked (filter (lambda (accepts) (not (any unheld? accepts)))
                                       (open-components run y t))))
                  (filter-map (lambda (z)
                                (and (any (lambda (uid)
                                            (any (lambda (a) (memq (kind-of uid) a)) blocked))
                                          (cdr z))
                                     (car z)))
                              now)))))
        (let ((edges (map (lambda (y) (cons (car y) (waits-on (car y)))) now)))
          (any (lambda (y) (reaches? edges y y '())) (map car now)))))

    ;; Whether a path of edges leads from a to b.
    (define (reaches? edges a b seen)
      (let ((next (cond ((assq a edges) => cdr) (else '()))))
        (or (memq b next)
            (any (lambda (c) (and (not (memq c seen)) (reaches? edges c b (cons c seen))))
                 next))))

    ;; From each end on a robot to the next start there, while a task
    ;; waited; and the same where that start is of a one-robot task, which
    ;; no task could have held for a while before it started.
    (define (latencies-where run ok?)
      (let ((waiting-at (waiting-counter run)))
        (let loop ((es (reverse (run-events run))) (next-start '()) (out '()))
          (if (null? es)
              out
              (let* ((e (car es)) (uid (list-ref e 4)) (next (assq uid next-start)))
                (if (eq? (cadr e) 'start)
                    (loop (cdr es) (cons (cons uid e) (remove (lambda (x) (eq? (car x) uid))
                                                              next-start))
                          out)
                    (loop (cdr es) next-start
                          (if (and next (ok? (cdr next)) (> (waiting-at (car e)) 0))
                              (cons (* 1000 (- (cadr next) (car e))) out)
                              out))))))))

    ;;> From the last release among the robots a task starts on to its
    ;;> start, in ms, for each task posed before that release: what the
    ;;> turns add, without the time its other robots were held for it,
    ;;> which 'hold means.
    (define (schedule-last-release-latencies run)
      (filter-map (lambda (t)
                    (let ((last (vector-ref (run-ready run) (car t))))
                      (and last (< (posed run t) last)
                           (* 1000 (- (car (span-of run t)) last)))))
                  (run-tasks run)))

    ;;; The ideal schedule: the same arrivals and rank rule, the measured
    ;;; work, no messages.  At each moment the waiting tasks, best rank
    ;;; first, each take for each component a free robot of a kind it
    ;;; accepts, those that accept one kind first, keeping them until they
    ;;; have all they need, as 'hold does; a robot taken is the one free
    ;;; longest.  Answers its makespan, and the start latency as the run's
    ;;; is measured: from a robot's release while a task waits to the next
    ;;; start on it.

    ;; The robots free for t's components, from free, sorted by release:
    ;; (taken . left), taken shorter than t's components when too few.
    (define (take-robots t free)
      (let loop ((kinds (list-sort (lambda (a b) (< (length a) (length b))) (task-kinds t)))
                 (free free) (taken '()))
        (if (null? kinds)
            (cons taken free)
            (let ((r (find (lambda (r) (memq (car r) (car kinds))) free)))
              (if r
                  (loop (cdr kinds) (remove (lambda (x) (eq? x r)) free) (cons r taken))
                  (loop (cdr kinds) free taken))))))

    (define (ideal-schedule run)
      ;; pool: (kind released . waited?) of each robot not running;
      ;; running: (end . pool entries); ranked: the tasks not started, best
      ;; rank first.
      (let ((worked (filter (lambda (t) (work-of run t)) (run-tasks run))))
        (let loop ((now 0)
                   (pool (map (lambda (r) (cons (cdr r) (cons 0 #f))) (run-robots run)))
                   (running '())
                   (ranked (list-sort (ranks-before? run) worked))
                   (last 0) (latencies '()))
          (let fill ((ws ranked)
                     (free (list-sort (lambda (a b) (< (cadr a) (cadr b))) pool))
                     (held '()) (left '()) (started '()) (latencies latencies))
            (cond
             ((and (pair? ws) (pair? free) (<= (posed run (car ws)) now))
              (let* ((got (take-robots (car ws) free)) (taken (car got)))
                (if (= (length taken) (task-robots (car ws)))
                    (fill (cdr ws) (cdr got) held left (cons (cons (car ws) taken) started)
                          (append (filter-map (lambda (r) (and (cddr r)
                                                               (* 1000 (- now (cadr r)))))
                                              taken)
                                  latencies))
                    (fill (cdr ws) (cdr got) (append taken held) (cons (car ws) left)
                          started latencies))))
             ((and (pair? ws) (pair? free))
              (fill (cdr ws) free held (cons (car ws) left) started latencies))
             (else
              (let* ((ranked (append (reverse left) ws))
                     (running (append (map (lambda (s) (cons (+ now (work-of run (car s)))
                                                             (cdr s)))
                                           started)
                                      running))
                     (later (filter (lambda (x) (> x now))
                                    (map (lambda (t) (posed run t)) ranked)))
                     (next (and (or (pair? running) (pair? later))
                                (apply min (append (map car running) later)))))
                (if (not next)
                    (list last latencies)
                    (let* ((ended (filter (lambda (r) (<= (car r) next)) running))
                           (waited? (any (lambda (t) (< (posed run t) next)) ranked)))
                      (loop next
                            (append free held
                                    (append-map (lambda (r)
                                                  (map (lambda (p)
                                                         (cons (car p) (cons (car r) waited?)))
                                                       (cdr r)))
                                                ended))
                            (remove (lambda (r) (<= (car r) next)) running)
                            ranked (apply max last (map car ended)) latencies))))))))))

    (define (percentile xs p)
      (if (null? xs)
          0
          (let ((v (list->vector (list-sort < xs))))
            (vector-ref v (min (- (vector-length v) 1)
                               (exact (floor (* p (vector-length v)))))))))

    (define (round-to x places)
      (let ((m (expt 10 places))) (/ (round (* x m)) m)))

    ;;> Prints a line "bench: NAME VALUE UNIT".
    (define (bench name value unit)
      (display "bench: ") (display name) (display " ") (display value)
      (display " ") (display unit) (newline))

    ;;> Prints the run's figures beside its ideal schedule's, each name
    ;;> starting with \var{prefix}, and tells the inversions on standard
    ;;> error.
    (define (print-schedule-figures run prefix)
      (define (line name value unit) (bench (string-append prefix "-" name) value unit))
      (let* ((tasks (run-tasks run))
             (makespan (schedule-makespan run))
             (robot-seconds (apply + (map (lambda (t) (* (task-robots t) (or (work-of run t) 0)))
                                          tasks)))
             (bound (max (/ robot-seconds (length (run-robots run)))
                         (apply max 0 (filter-map (lambda (t) (work-of run t)) tasks))))
             (ideal-run (ideal-schedule run))
             (ideal (car ideal-run))
             (inversions (inversions run))
             (one-robot? (lambda (s) (= 1 (task-robots (list-ref tasks (list-ref s 2))))))
             (latencies (latencies-where run (lambda (s) #t)))
             (one-robot-latencies (latencies-where run one-robot?))
             (last-release (schedule-last-release-latencies run)))
        (line "tasks" (length tasks) "")
        (line "completed" (run-completed run) "")
        (line "lost" (- (length tasks) (run-completed run)) "")
        (line "double-bookings" (double-bookings run) "")
        (line "deadlocks" (deadlocks run) "")
        (line "stalls" (stalls run) "")
        (for-each (lambda (xy) (tell-inversion! run xy)) inversions)
        (line "priority-inversions" (length inversions) "")
        (line "makespan" (round-to makespan 2) "s")
        (line "ideal-makespan" (round-to ideal 2) "s")
        (line "makespan-over-ideal" (round-to (/ makespan ideal) 3) "x")
        (line "lower-bound" (round-to bound 2) "s")
        (line "makespan-over-bound" (round-to (/ makespan bound) 3) "x")
        (line "start-latency-p50" (round-to (percentile latencies 0.5) 1) "ms")
        (line "start-latency-p95" (round-to (percentile latencies 0.95) 1) "ms")
        (line "ideal-start-latency-p50" (round-to (percentile (cadr ideal-run) 0.5) 1) "ms")
        (line "ideal-start-latency-p95" (round-to (percentile (cadr ideal-run) 0.95) 1) "ms")
        (line "start-latency-one-robot-p50"
              (round-to (percentile one-robot-latencies 0.5) 1) "ms")
        (line "start-latency-one-robot-p95"
              (round-to (percentile one-robot-latencies 0.95) 1) "ms")
        (line "start-latency-last-release-p50" (round-to (percentile last-release 0.5) 1) "ms")
        (line "start-latency-last-release-p95" (round-to (percentile last-release 0.95) 1) "ms")
        (line "utilization"
              (round-to (* 100 (/ robot-seconds (* (length (run-robots run)) makespan))) 1) "%")
        (for-each
         (lambda (k)
           (line (string-append "wait-p95-priority-" (number->string k))
                 (round-to (percentile (filter-map (lambda (t)
                                                     (and (= (task-priority t) k)
                                                          (span-of run t)
                                                          (- (car (span-of run t))
                                                             (posed run t))))
                                                   tasks)
                                       0.95)
                           2)
                 "s"))
         (delete-duplicates (list-sort < (map task-priority tasks))))))))
