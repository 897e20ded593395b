;;;; pose-task (thesis §4.2, appendix A.7 new-task.scm).
;;
;; It asks the lab who is capable (request-exclusive, or request for a
;; shared component), ranks candidates by each component's metric, gives
;; each in priority order the best not chosen, frees every unused
;; promise, and runs the team.  Beyond the thesis: docs/allocation.md.

;;; pose-task

;;> How pose-task gives components their robots: \scheme{greedy}, the
;;> thesis's rule (resolve-conflicts), or \scheme{optimal}, the least
;;> total of the components' measures ((murdoch assign)); a component
;;> whose metric is not one measure keeps the greedy rule.
(define pose-task-assignment (make-parameter 'greedy))

;;> The priority of the tasks posed here, a real: when tasks posed at
;;> once want the same robots, the higher wins (see negotiate).
(define pose-task-priority (make-parameter 0))

;;> How many times a task whose robots another task holds tries again
;;> before it answers \scheme{not-enough-takers}.
(define pose-task-retries (make-parameter (lab-default 'pose-task-retries)))

;;> Seconds of the first wait before trying again; each wait is drawn at
;;> random below this, doubled for each try before it.
(define pose-task-backoff (make-parameter (lab-default 'pose-task-backoff)))

;;> Robots that pose-task gives no component to: a task that lost a
;;> robot renegotiates without it (life-cycle.scm).
(define pose-task-excluded (make-parameter '()))

;; Whether a negotiation that found too few takers asks the whole lab
;; why and writes it (explain-no-takers): a waiting task's tries do not.
(define pose-task-explain (make-parameter #t))

;; The reservation name a negotiation holds its robots under, or #f for
;; a new one: a started task's id, so its reservations name the task.
(define pose-task-reservation (make-parameter #f))

(define (failed-result? r)
  (and (list? r) (= (length r) 3) (eq? (car r) 'error) (string? (caddr r))))

(for-each sandbox-parameter!
          (list pose-task-assignment pose-task-priority pose-task-retries
                pose-task-backoff pose-task-excluded))

(define (component-type layout)
  (if (null? (car layout)) 'non-exclusive 'exclusive))

;; The node's poses part: the poses made here, counted, and those
;; negotiating, which a rival's call (receive-rival) finds by name; its
;; lock is over both.
(define-record-type poses
  (make-poses count negotiating lock)
  poses?
  (count poses-count poses-count-set!)
  (negotiating poses-negotiating poses-negotiating-set!)
  (lock poses-lock))

(define-syntax the-poses (syntax-rules () ((_) (node-poses *node*))))

(define (open-poses!) (node-poses-set! (this-node) (make-poses 0 '() (make-mutex 'poses))))

;; A pose negotiating here: its name, rank, and its rivals' ranks.
(define-record-type negotiation
  (make-negotiation name rank rivals)
  negotiation?
  (name negotiation-name)
  (rank negotiation-rank)
  (rivals negotiation-rivals negotiation-rivals-set!))

(define (with-poses thunk) (with-lock (poses-lock (the-poses)) thunk))

;;> A key of this address space's own for a task named \var{task-name},
;;> NAME@UID/N: a started task's id and its reservations' name, so the
;;> same task posed twice at once never shares a robot.
(define (task-key task-name)
  (numbered-key task-name ""))

;;> A key as task-key makes, NAME@UID/lab-N, for a task handed to the lab
;;> (detached.scm): UID the member that first coordinated it, the key its
;;> name wherever it is coordinated later, and never one of task-key's,
;;> which a member started again counts from 1 again.
(define (lab-task-key task-name)
  (numbered-key task-name lab-key-mark))

(define lab-key-mark "lab-")

;;> Whether \var{key} was made by lab-task-key: the pose that holds it
;;> may be coordinated elsewhere than UID.
(define (lab-task-key? key)
  (let* ((s (symbol->string key))
         (from (+ 1 (or (last-index s #\/ (string-length s)) (string-length s))))
         (to (+ from (string-length lab-key-mark))))
    (and (<= to (string-length s)) (string=? lab-key-mark (substring s from to)))))

(define (numbered-key task-name mark)
  (let ((n (with-poses (lambda ()
                        (poses-count-set! (the-poses) (+ (poses-count (the-poses)) 1))
                        (poses-count (the-poses))))))
    (string->symbol (string-append (symbol->string task-name) "@"
                                   (symbol->string (local-aspace-uid)) "/" mark
                                   (number->string n)))))

;;> The task name and the poser's uid of \var{key} (a symbol or string
;;> NAME@UID/N, as task-key makes), as two strings in a list, or #f for a
;;> key task-key did not make.
(define (task-key-parts key)
  (let* ((s (if (symbol? key) (symbol->string key) key))
         (slash (last-index s #\/ (string-length s)))
         (at (and slash (last-index s #\@ slash))))
    (and at (list (substring s 0 at) (substring s (+ at 1) slash)))))

(define (reservation-aspace-uid name)
  (let ((parts (task-key-parts name)))
    (and parts (string->symbol (cadr parts)))))

(define (last-index s char end)
  (let loop ((i (- end 1)))
    (cond ((< i 0) #f)
          ((char=? (string-ref s i) char) i)
          (else (loop (- i 1))))))

;;> Poses a task (thesis §4.2): \var{capability-list}, \var{metrics} and
;;> \var{procs} have one entry per component, most important first, or
;;> as \var{priorities} says: a real for each component, the higher
;;> choosing first.  Answers the list of the components' results, in
;;> component order, or \scheme{not-enough-takers} when some component
;;> finds no distinct capable robot; then every reservation made for it
;;> is freed.
(define (pose-task task-name num-robots capability-list metrics procs . priorities)
  (let ((team (apply negotiate task-name num-robots capability-list metrics
                     procs priorities)))
    (if (symbol? team)
        team
        (let ((uids (map winner-uid (negotiated-winners team))))
          (for-each (lambda (i uid) (progress "  component " i " starts on " uid))
                    (iota (length uids) 1) uids)
          (let ((results ((with-team-proc-maker (negotiated-winners team)
                                                (negotiated-types team) procs
                                                (posed-component
                                                 (negotiated-name team))))))
            ;; Applied promises are of no more use here.
            (for-each (lambda (winner type)
                        (if (eq? type 'exclusive)
                            (release-proxy! (winner-promise winner))))
                      (negotiated-winners team) (negotiated-types team))
            (for-each (lambda (i uid result)
                        (if (failed-result? result)
                            (progress "  component " i " failed on " uid ": "
                                      (caddr result))
                            (progress "  component " i " done on " uid ": "
                                      (abridged result 50))))
                      (iota (length uids) 1) uids results)
            results)))))

;;> The negotiation of pose-task without the running: answers (winners
;;> type-list name), where winners are the chosen (uid promise-or-#t)
;;> entries and name the reservation name they were won under, or
;;> \scheme{not-enough-takers}.  Every promise not among the winners is
;;> freed.  Tasks that want the same robots take turns by rank
;;> (pose-task-priority, then reservation name): docs/allocation.md.
(define (negotiate task-name num-robots capability-list metrics procs . priorities)
  (let ((priorities (if (pair? priorities)
                        (car priorities)
                        (thesis-priorities num-robots))))
    (check-task task-name num-robots capability-list metrics procs priorities)
    (let* ((layouts (map capability-layout capability-list))
           (type-list (map component-type layouts))
           (name (or (pose-task-reservation) (task-key task-name)))
           (task (make-pose name layouts type-list (map metric-keys metrics)
                            procs priorities)))
      (progress task-name ": " (length procs) " components")
      (while-negotiating name (lambda () (negotiate-by-tries task 1))))))

;;> The parts of negotiate's answer, (WINNERS TYPES NAME), by name: its
;;> winners and their types, in component order, the reservation's name,
;;> and a winner's uid and promise (#t for a non-exclusive component).
(define (negotiated-winners answer) (car answer))
(define (negotiated-types answer) (cadr answer))
(define (negotiated-name answer) (car (cddr answer)))
(define (winner-uid winner) (car winner))
(define (winner-promise winner) (cadr winner))

(define-record-type pose
  (make-pose name layouts type-list keys-list procs priorities)
  pose?
  (name pose-name)
  (layouts pose-layouts)
  (type-list pose-type-list)
  (keys-list pose-keys-list)
  (procs pose-procs)
  (priorities pose-priorities)
  (tried pose-tried pose-tried-set!))    ; the last try's candidates' uids

(define (negotiate-by-tries task n)
  (let ((outcome (if (outranking-rivals-negotiating? (pose-name task))
                     'waiting
                     (try task))))
    (cond ((pair? outcome) outcome)
          ((and (<= n (pose-task-retries))
                (or (memq outcome '(waiting outranked)) (contended! task)))
           (back-off! n outcome)
           (negotiate-by-tries task (+ n 1)))
          (else
           (if (pose-task-explain)
               (explain-no-takers (pose-name task) (pose-layouts task) (current-error-port)))
           'not-enough-takers))))

;; One round: (winners type-list name), not-enough-takers, or outranked;
;; on failure everything is freed.
(define (try task)
  (let* ((type-list (pose-type-list task))
         (round (request-components (pose-name task) (round-components task)))
         (responses (map without-excluded type-list (map car round))))
    (pose-tried-set! task (append-map (lambda (r) (map car r)) responses))
    (for-each (lambda (i layout response)
                (progress "  component " i " needs " layout ": candidates "
                          (map car response)))
              (iota (length responses) 1) (pose-layouts task) responses)
    (let ((winners (and (not (any null? responses))
                        (choose (map measured-response responses (pose-keys-list task)
                                     (map cadr round))
                                (pose-keys-list task) (pose-priorities task)))))
      (cond
       ((not winners) (give-up responses type-list 'not-enough-takers))
       ((not (commit! (pose-name task))) (give-up responses type-list 'outranked))
       (else
        (release-runners-up responses type-list winners)
        (for-each (lambda (i w) (progress "  component " i " goes to " (car w)))
                  (iota (length winners) 1) winners)
        (list winners type-list (pose-name task)))))))

;; What runs component k, proc, on its robot: listed there
;; (run-posed-component), so the live view finds how it ended.
(define (posed-component name)
  (let ((poser (local-aspace-uid)))
    (lambda (k proc)
      (sendable-lambda () (run-posed-component name k poser proc)))))

;; What request-components asks the lab for each component, with the
;; askings of its metric.
(define (round-components task)
  (map (lambda (type layout proc keys)
         (list type layout (if (eq? type 'exclusive) proc t) (asking-procs keys)))
       (pose-type-list task) (pose-layouts task) (pose-procs task)
       (pose-keys-list task)))

(define (check-task task-name num-robots capability-list metrics procs priorities)
  (if (not (and (exact-integer? num-robots) (>= num-robots 0)))
      (error "pose-task: num-robots is a whole number" num-robots))
  (if (not (symbol? task-name))
      (error "pose-task: the task name is not a symbol" task-name))
  (if (not (and (list? capability-list) (list? metrics) (list? procs)))
      (error "pose-task: capabilities, metrics and procedures are lists"))
  (if (not (= num-robots (length capability-list) (length metrics)
              (length procs)))
      (error "pose-task: num-robots, capabilities, metrics and procedures do not agree"
             num-robots (length capability-list) (length metrics)
             (length procs)))
  (if (not (and (list? priorities) (= num-robots (length priorities))
                (every real? priorities)))
      (error "pose-task: priorities are a real for each component" priorities))
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
            procs)
  (if (not (real? (pose-task-priority)))
      (error "pose-task: (pose-task-priority) is a real number" (pose-task-priority)))
  (if (not (memq (pose-task-assignment) '(greedy optimal)))
      (error "pose-task: (pose-task-assignment) is greedy or optimal"
             (pose-task-assignment))))

;; response without the robots of (pose-task-excluded), whose promises
;; are freed.
(define (without-excluded type response)
  (let ((excluded (pose-task-excluded)))
    (if (null? excluded)
        response
        (let ((out (filter (lambda (e) (memq (car e) excluded)) response)))
          (release-runners-up (list out) (list type) '())
          (remove (lambda (e) (memq e out)) response)))))

(define (give-up responses type-list outcome)
  (release-runners-up responses type-list '())
  (progress "  " outcome "; every reservation freed")
  outcome)

;; Applies to #f, all at once, each promise that did not win its component:
;; the exact entry, not its robot, since a robot may have promised two.
(define (release-runners-up responses type-list winners)
  (let ((entries (append-map (lambda (response type)
                               (if (eq? type 'exclusive)
                                   (remove (lambda (entry) (memq entry winners)) response)
                                   '()))
                             responses type-list)))
    (for-each forget-promise! entries (apply-each (map winner-promise entries) '(#f)))))

(define (forget-promise! entry r)       ; once r, its application, freed it
  (let ((why (cond ((not (result-ok? r)) (result-value r))
                   ((proxy-procedure-ref (winner-promise entry))
                    (release-proxy! (winner-promise entry))
                    #f)
                   (else "not a promise"))))
    (if why (log-warn "releasing " (winner-uid entry) ": " why))))
