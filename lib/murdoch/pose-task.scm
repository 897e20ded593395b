;;;; pose-task (thesis §4.2, appendix A.7 new-task.scm) and MOVER's
;;;; dynamic teams (§3.3.3): with-team and on-list.
;;
;; The user poses a task as components, each with the capabilities it
;; needs, a metric to rank candidates and the procedure to run.  pose-task
;; asks the lab who is capable (request-exclusive for components that need
;; a resource to themselves, request otherwise), ranks each component's
;; candidates by its metric, gives each component the best candidate not
;; already chosen for a more important one (the components come in
;; priority order), frees every promise it will not use, and runs the
;; components as a team.

;;; Progress

;;> A port on which pose-task tells what it is doing, or #f for silence.
(define pose-task-progress (make-parameter #f))

;; Received code that sets these sets them for its own call only.
(sandbox-parameter! pose-task-progress)

(define (progress . parts)
  (let ((out (pose-task-progress)))
    (when out
      ;; One write-string a line, so lines from threads do not interleave.
      (write-string
       (call-with-output-string
         (lambda (line)
           (write-string "pose-task: " line)
           (for-each (lambda (p)
                       (if (string? p) (write-string p line) (write p line)))
                     parts)
           (newline line)))
       out)
      (flush-output-port out))))

;;; Metrics

;; A metric compares two candidates, (uid promise-or-result) entries, and
;; answers #t when the first is better, as in the thesis.  Those made by
;; metric-by also carry their measure, so that pose-task can ask each
;; candidate once, not once per comparison: the same choice, fewer messages.
;; A measure is a procedure of a uid, or an asking: what a candidate
;; answers to one procedure, scored here, which pose-task sends to every
;; candidate at once.
(define-record-type asking
  (make-asking proc score)
  asking?
  (proc asking-proc)
  (score asking-score))

;;> A metric that prefers the candidate with the smaller
;;> \scheme{(measure uid)}: a number for a candidate's uid.
(define (metric-by measure)
  (lambda (entry1 entry2)
    (< (measure-one measure (car entry1)) (measure-one measure (car entry2)))))

;;> A metric that prefers the candidate whose answer to \var{proc},
;;> applied there, has the smaller \scheme{(score answer)}.  pose-task
;;> asks all of a component's candidates with one message each.
(define (metric-by-asking proc score)
  (metric-by (make-asking proc score)))

(define (measure-one measure uid)
  (if (asking? measure)
      ((asking-score measure) (ask uid (asking-proc measure)))
      (measure uid)))

(define metric-by-code (procedure-code (metric-by #f)))

(define (metric-measure metric)
  (and (procedure? metric) (not (opcode? metric))
       (eq? (procedure-code metric) metric-by-code)
       (vector-ref (procedure-vars metric) 0)))

;;> The distance in mm between two reckon positions, (x y theta 0).
(define (reckon-distance-between p q)
  (let ((dx (- (car p) (car q))) (dy (- (cadr p) (cadr q))))
    (sqrt (+ (* dx dx) (* dy dy)))))

;; What candidate uid answers to proc, asked point to point.
(define (ask uid proc)
  (remote-apply (uid->aspace uid) proc))

;;> Prefers the candidate closest to \var{target}, (x y theta 0) as reckon
;;> answers, by each candidate's safe-reckon.
(define (location-metric-maker target)
  (metric-by-asking safe-reckon
                    (lambda (position) (reckon-distance-between target position))))

;;> Prefers the candidate with the lowest system load.
(define (load-metric-maker)
  (metric-by-asking get-system-load string->number))

;;> The load metric of Figure 4.6.
(define load-metric (load-metric-maker))

;;> The opposite preference: the worst candidate by \var{metric} first.
(define (reverse-metric metric)
  (let ((measure (metric-measure metric)))
    (cond ((asking? measure)
           (let ((score (asking-score measure)))
             (metric-by-asking (asking-proc measure) (lambda (a) (- (score a))))))
          (measure (metric-by (lambda (uid) (- (measure uid)))))
          (else (lambda (a b) (metric b a))))))

;; Sorts a component's candidates by its metric; no metric: at random.
(define (sort-response response metric)
  (cond
   ((not (procedure? metric)) (shuffle response))
   ((metric-measure metric)
    => (lambda (measure)
         (let ((measured (map cons (measure-all measure (map car response))
                              response)))
           (progress "  measured " (map (lambda (m) (list (cadr m) (car m)))
                                        measured))
           (map cdr (list-sort (lambda (a b) (< (car a) (car b))) measured)))))
   (else (list-sort metric response))))

;; Measures every candidate at once: the answers' round trips overlap.  A
;; candidate that cannot be measured (it died, did not answer in time, or
;; its answer does not score) measures +inf.0, and so comes last.
(define (measure-all measure uids)
  (if (asking? measure)
      (map (lambda (answer)
             (let ((score (and (cadr answer)
                               (guard (e (#t #f))
                                 ((asking-score measure) (car (cddr answer)))))))
               (if (real? score) score +inf.0)))
           (remote-apply-all (map uid->aspace uids) (asking-proc measure)))
      (map thread-join!
           (map (lambda (uid)
                  (thread-start!
                   (make-thread (lambda () (guard (e (#t +inf.0)) (measure uid))))))
                uids))))

(define (shuffle ls)
  (map cdr (list-sort (lambda (a b) (< (car a) (car b)))
                      (map (lambda (x) (cons (random-real) x)) ls))))

;;; pose-task

;; Whether a component needs resources to itself, from its layout.
(define (component-type layout)
  (if (null? (car layout)) 'non-exclusive 'exclusive))

(define *poses* 0)

;; Reservations are made under a name of this pose's own, so that the same
;; task posed twice at once, from here or elsewhere, never shares a robot.
(define (reservation-name task-name)
  (set! *poses* (+ *poses* 1))
  (string->symbol (string-append (symbol->string task-name) "@"
                                 (symbol->string (local-aspace-uid)) "#"
                                 (number->string *poses*))))

(define (t) #t)

;;> Poses a task (thesis §4.2): \var{capability-list}, \var{metrics} and
;;> \var{procs} have one entry per component, most important first.
;;> Answers the list of the components' results, in component order, or
;;> \scheme{not-enough-takers} when some component finds no distinct
;;> capable robot; then every reservation made for it is freed.
(define (pose-task task-name num-robots capability-list metrics procs)
  (let ((team (negotiate task-name num-robots capability-list metrics procs)))
    (if (symbol? team)
        team
        (let ((uids (map car (car team))))
          (for-each (lambda (i uid) (progress "  component " i " starts on " uid))
                    (iota (length uids) 1) uids)
          (let ((results ((with-team-proc-maker (car team) (cadr team) procs))))
            ;; Applied promises are of no more use here.
            (for-each (lambda (winner type)
                        (if (eq? type 'exclusive) (release-proxy! (cadr winner))))
                      (car team) (cadr team))
            (for-each (lambda (i uid result)
                        (progress "  component " i " done on " uid ": "
                                  (abridged result 50)))
                      (iota (length uids) 1) uids results)
            results)))))

;;> The negotiation of pose-task without the running: answers (winners
;;> type-list), where winners are the chosen (uid promise-or-#t) entries,
;;> or \scheme{not-enough-takers}.  Every promise not among the winners is
;;> freed.
(define (negotiate task-name num-robots capability-list metrics procs)
  (check-task task-name num-robots capability-list metrics procs)
  (let* ((layouts (map capability-layout capability-list))
         (type-list (map component-type layouts))
         (name (reservation-name task-name))
         (responses (map (lambda (layout type proc)
                           (if (eq? type 'exclusive)
                               (request-exclusive layout name proc)
                               (request (cadr layout) t)))
                         layouts type-list procs)))
    (progress task-name ": " (length procs) " components")
    (for-each (lambda (i layout response)
                (progress "  component " i " needs " layout ": candidates "
                          (map car response)))
              (iota (length procs) 1) layouts responses)
    (if (any null? responses)
        (give-up responses type-list '())
        (let* ((sorted-lists (map sort-response responses metrics))
               (winners (resolve-conflicts sorted-lists)))
          (cond
           ((not winners) (give-up responses type-list '()))
           (else
            (release-runners-up responses type-list winners)
            (for-each (lambda (i w) (progress "  component " i " goes to " (car w)))
                      (iota (length winners) 1) winners)
            (list winners type-list)))))))

(define (check-task task-name num-robots capability-list metrics procs)
  (if (not (symbol? task-name))
      (error "pose-task: the task name is not a symbol" task-name))
  (if (not (and (list? capability-list) (list? metrics) (list? procs)))
      (error "pose-task: capabilities, metrics and procedures are lists"))
  (if (not (= num-robots (length capability-list) (length metrics)
              (length procs)))
      (error "pose-task: num-robots, capabilities, metrics and procedures do not agree"
             num-robots (length capability-list) (length metrics)
             (length procs)))
  ;; Checked before anything is reserved, so that a bad component late in
  ;; the list leaves no reservation behind for the ones before it.
  (for-each (lambda (c)
              (check-subjects "pose-task" (apply append (capability-layout c))))
            capability-list)
  (for-each (lambda (m)
              (if (and m (not (procedure? m)))
                  (error "pose-task: a metric is a procedure or #f" m)))
            metrics)
  (for-each (lambda (p)
              (if (not (procedure? p))
                  (error "pose-task: a component's procedure is not a procedure" p)))
            procs))

;; Frees every promise but the winners' and answers not-enough-takers.
(define (give-up responses type-list winners)
  (release-runners-up responses type-list winners)
  (progress "  not enough takers; every reservation freed")
  'not-enough-takers)

;; Applies to #f each promise that did not win its component: the exact
;; entry, not its robot, since a robot may have promised two components.
(define (release-runners-up responses type-list winners)
  (for-each (lambda (response type)
              (if (eq? type 'exclusive)
                  (for-each (lambda (entry)
                              (if (not (memq entry winners))
                                  (guard (e (#t (log-warn "releasing " (car entry)
                                                          ": " (error-object-message e))))
                                    ((cadr entry) #f)
                                    (release-proxy! (cadr entry)))))
                            response)))
            responses type-list))

;;> Takes lists of (uid ...) entries, each sorted best first, in priority
;;> order, and picks for each the first entry whose robot no earlier list
;;> has taken; answers the picks in order, or #f if a list runs out.
(define (resolve-conflicts sorted-lists)
  (let loop ((lists sorted-lists) (chosen '()))
    (if (null? lists)
        (reverse chosen)
        (let ((pick (find (lambda (entry) (not (assq (car entry) chosen)))
                          (car lists))))
          (and pick (loop (cdr lists) (cons pick chosen)))))))

;;; Dynamic teams

;;> The robots of the team being run.
(define current-team (make-parameter '()))
(sandbox-parameter! current-team)

;;> Runs \var{body} with \var{uids} as the current team.
(define-syntax with-team
  (syntax-rules ()
    ((with-team uids body ...)
     (parameterize ((current-team uids)) body ...))))

;;> Runs each procedure of \var{procs} on a robot of the team, all at once,
;;> with MOVER's options: (fixed UIDS) pairs the procedures with UIDS;
;;> (all) with the whole team; (arbitrary N [from UIDS]) with N picked at
;;> random; (timeout SECONDS), 0 for (task-timeout); (collect PROC) to
;;> combine the results (default: the list, in order); (on-error PROC),
;;> applied to the uid and the error, whose value stands for the result;
;;> (debug #t) to tell each start and end.
(define-syntax on-list
  (syntax-rules ()
    ((on-list (option ...) procs)
     (exec-on (list (on-list-option option) ...) procs))))

(define-syntax on-list-option
  (syntax-rules (from)
    ((_ (arbitrary n from uids)) (list 'arbitrary n uids))
    ((_ (key arg ...)) (list 'key arg ...))))

(define (option options key default)
  (cond ((assq key options) => cadr) (else default)))

;; Macros are defined before their first use, which Chibi requires.
;;> A thunk that runs the task's components on its chosen robots, as a
;;> team: an exclusive component by applying its winner's promise to #t, a
;;> non-exclusive one by running its procedure on the winner.
(define (with-team-proc-maker task-uids type-list procs)
  (let ((proclist (map (lambda (task-uid proc type)
                         (if (eq? type 'exclusive)
                             (let ((promise (cadr task-uid)))
                               (sendable-lambda () (promise #t)))
                             proc))
                       task-uids procs type-list))
        (uids (map car task-uids)))
    (lambda ()
      (with-team uids
        (on-list ((fixed uids)) proclist)))))

;;> Seconds a component may run before its caller gives up on it, when
;;> on-list is not given a timeout: pose-task's components, for one.  The
;;> component is told as failed (see on-error), and stops on its robot at
;;> its next robot command or remote call (abandon.scm); until then an
;;> exclusive one holds its subjects.
(define task-timeout (make-parameter 600))
(sandbox-parameter! task-timeout)

(define (select-robots options)
  (cond
   ((assq 'fixed options) => cadr)
   ((assq 'arbitrary options)
    => (lambda (o)
         (let ((pool (shuffle (if (pair? (cddr o)) (car (cddr o)) (current-team)))))
           (take pool (min (cadr o) (length pool))))))
   (else (current-team))))


(define (exec-on options procs)
  (let* ((uids (select-robots options))
         (seconds (let ((s (option options 'timeout 0)))
                    (if (and (number? s) (positive? s)) s (task-timeout))))
         (on-error (option options 'on-error team-error))
         (collect (option options 'collect list))
         (debug? (option options 'debug #f))
         (port (pose-task-progress)))   ; threads do not inherit parameters
    (if (not (= (length uids) (length procs)))
        (error "on-list: the team and the procedures do not pair up"
               uids (length procs)))
    (apply collect
           (join-or-interrupt
            (map (lambda (uid proc)
                   (thread-start!
                    (make-thread
                     (lambda ()
                       (parameterize ((pose-task-progress port))
                         (run-on uid proc seconds on-error debug?))))))
                 uids procs)))))

;; The threads' results, in order.  Left before they are all done (Ctrl-C
;; at the REPL interrupts the join), the threads are interrupted too: each
;; gives up its component, which stops on its robot (abandon.scm).
(define (join-or-interrupt threads)
  (undo-on-raise (lambda () (for-each thread-interrupt! threads))
                 (lambda () (map thread-join! threads))))

;; Runs one component on its robot; an error or a timeout goes to on-error.
(define (run-on uid proc seconds on-error debug?)
  (if debug? (progress "  " uid " starts"))
  (let ((result (guard (e (#t (on-error uid e)))
                  (if (eq? uid (local-aspace-uid))
                      (apply-here-by proc seconds)
                      (parameterize ((remote-timeout seconds))
                        (remote-apply (uid->aspace uid) proc))))))
    (if debug? (progress "  " uid " done: " result))
    result))

;; A component that this address space won runs here, in a thread of its
;; own, so that seconds bound it as they bound one elsewhere: the wait
;; ends, by timeout or interrupt, and the component is given up
;; (abandon.scm).
(define (apply-here-by proc seconds)
  (let* ((outcome #f)
         (runner (make-thread
                  (lambda ()
                    (set! outcome
                          (guard (e (#t (cons 'raised e)))
                            (cons 'value (remote-apply (local-aspace) proc))))))))
    (thread-start! runner)
    (dynamic-wind (lambda () #f)
                  (lambda () (thread-join! runner seconds #f))
                  (lambda () (if (not outcome) (abandon-thread! runner))))
    (cond ((not outcome)
           (error (string-append "no answer within " (number->string seconds) " s")))
          ((eq? (car outcome) 'raised) (raise (cdr outcome)))
          (else (cdr outcome)))))

;; The default on-error: tell, and let (error UID MESSAGE) stand for the
;; result, so the other components' results still come back.
(define (team-error uid e)
  (let ((message (if (remote-error? e)
                     (remote-error-message e)
                     (if (error-object? e) (error-object-message e) e))))
    (log-warn "component on " uid " failed: " message)
    (list 'error uid message)))

;;; What the thesis's task procedures call

;;> Sorts \var{ls} by \var{less?} (the thesis's sort-list).
(define (sort-list ls less?) (list-sort less? ls))

;;> A thunk answering random integers from 0 below \var{n}.
(define (make-maxrandom n) (lambda () (random-integer n)))
