;;;; Tasks posed at once, part of (murdoch task pose-task): how rival
;;;; posers of tasks that want the same robots rank, and which gives way.

;; A rank is (priority name), as it travels to rival posers; the higher
;; priority outranks, then the smaller name, so that no two ranks tie.
(define (rank-priority rank) (car rank))
(define (rank-name rank) (cadr rank))

(define (outranks? rank1 rank2)
  (or (> (rank-priority rank1) (rank-priority rank2))
      (and (= (rank-priority rank1) (rank-priority rank2))
           (string<? (symbol->string (rank-name rank1))
                     (symbol->string (rank-name rank2))))))

(define (own-rank name) (list (pose-task-priority) name))

;; Runs thunk with name negotiating here, and then no longer.
(define (while-negotiating name thunk)
  (dynamic-wind
   (lambda ()
     (with-poses
      (lambda ()
        (poses-negotiating-set! (the-poses) (cons (make-negotiation name (own-rank name) '())
                                  (poses-negotiating (the-poses)))))))
   thunk
   (lambda ()
     (with-poses (lambda () (poses-negotiating-set! (the-poses) (without-name name)))))))

;; The negotiations here, but name's; and name's.  Under the poses' lock.
(define (without-name name)
  (remove (lambda (n) (eq? (negotiation-name n) name)) (poses-negotiating (the-poses))))
(define (negotiation-named name)
  (find (lambda (n) (eq? (negotiation-name n) name)) (poses-negotiating (the-poses))))

;;> What a pose that wants robots held by pose \var{name} calls where
;;> \var{name} was posed, with its \var{rank} (priority name): answers #t
;;> when \var{name} is still negotiating here, and will hear of it.
(define (receive-rival name rank)
  ;; A rank comes from another peer, and is compared under the lock.
  (if (not (and (list? rank) (= (length rank) 2) (real? (rank-priority rank))
                (symbol? (rank-name rank))))
      (error "receive-rival: a rank is (priority name)" rank))
  (with-poses
   (lambda ()
     (let ((n (negotiation-named name)))
       (and n
            (begin (negotiation-rivals-set! n (cons rank (negotiation-rivals n)))
                   #t))))))

;;> The poses negotiating here, each as (name rank rival-rank ...): its
;;> (priority name) and those of the poses that want robots it holds.
(define (pose-negotiations)
  (with-poses
   (lambda ()
     (map (lambda (n)
            (cons* (negotiation-name n) (negotiation-rank n) (negotiation-rivals n)))
          (poses-negotiating (the-poses))))))

;; The ranks of the rivals that outrank pose name.
(define (outranking-rivals name)
  (with-poses
   (lambda ()
     (let ((n (negotiation-named name)))
       (filter (lambda (rank) (outranks? rank (negotiation-rank n)))
               (negotiation-rivals n))))))

;; Commits pose name to the winners it has: #f if a rival outranks it.
;; Rivals heard of later find it no longer negotiating.
(define (commit! name)
  (with-poses
   (lambda ()
     (let ((n (negotiation-named name)))
       (and (not (any (lambda (rank) (outranks? rank (negotiation-rank n)))
                      (negotiation-rivals n)))
            (begin (poses-negotiating-set! (the-poses) (without-name name)) #t))))))

;; Whether a rival that outranks pose name is still negotiating where it
;; was posed.  Rivals that are done are forgotten, so that they no longer
;; make it give way.
(define (outranking-rivals-negotiating? name)
  (let ((done (remove rival-negotiating? (outranking-rivals name))))
    (with-poses
     (lambda ()
       (let ((n (negotiation-named name)))
         (negotiation-rivals-set!
          n (remove (lambda (rank) (member rank done)) (negotiation-rivals n))))))
    (pair? (outranking-rivals name))))

(define (rival-negotiating? rank)
  (let ((name (rank-name rank)))
    (or (guard (e (#t #f))
          (and (assq name (remote-apply (uid->aspace (reservation-aspace-uid name))
                                        pose-negotiations))
               #t))
        (and (lab-task-key? name)
             (pair? (at-lab-task-holders (sendable-lambda ()
                                           (and (assq name (pose-negotiations)) #t))))))))

;; The uids of the members holding detached tasks at which thunk answers
;; #t: where a pose of a task handed to the lab negotiates once another
;; member took it over, its key naming the first.
(define (at-lab-task-holders thunk)
  (filter-map (lambda (answer) (and (eq? (cadr answer) #t) (car answer)))
              (guard (e (#t '())) (request 'lab-tasks thunk))))

;; After a try that found too few robots: whether another may do better,
;; when other poses hold robots it could use and are told of this one's
;; rank, or when such a robot is free now that was no candidate in the
;; try (its holder, told to give way, let it go in between).
(define (contended! task)
  (let* ((statuses (capable-statuses (pose-layouts task) (pose-type-list task)))
         (holders (rival-holders (pose-name task) statuses)))
    (for-each (lambda (holder) (tell-rival! holder (own-rank (pose-name task))))
              holders)
    (or (pair? holders) (freed-since? (pose-tried task) statuses))))

;; (uid status ...) of each robot capable of an exclusive component, a
;; status for each of the component's exclusive subjects.
(define (capable-statuses layouts type-list)
  (append-map
   (lambda (layout type)
     (if (eq? type 'exclusive)
         (let ((subjects (car layout)))
           (map (lambda (answer) (cons (car answer) (cadr answer)))
                (request (apply append layout)
                         (sendable-lambda () (map topic-status subjects)))))
         '()))
   layouts type-list))

;; The names under which other tasks hold those subjects.
(define (rival-holders name statuses)
  (delete-duplicates
   (filter (lambda (status)
             (and (symbol? status) (not (memq status (list name 'shared)))))
           (append-map cdr statuses))))

(define (freed-since? tried statuses)
  (any (lambda (s) (and (every null? (cdr s))
                        (not (memq (car s) tried))
                        (not (memq (car s) (pose-task-excluded)))))
       statuses))

(define (tell-rival! holder rank)
  (let ((uid (reservation-aspace-uid holder)))
    (if (and uid
             (not (guard (e (#t (log-warn "telling " holder " of " rank ": "
                                          (error-message e))
                                #f))
                    (remote-apply (uid->aspace uid) receive-rival holder rank)))
             (lab-task-key? holder))
        (at-lab-task-holders (sendable-lambda () (receive-rival holder rank))))))

;; Waits a random while, below (pose-task-backoff) doubled for each try
;; before try n.  Each process draws from its own seed: Chibi starts every
;; process's default source alike, and posers that drew alike would
;; collide again.
(define (back-off! n outcome)
  (let ((seconds (* (backoff-random) (pose-task-backoff) (expt 2 (- n 1)))))
    (progress "  try " n ": " outcome "; trying again in "
              (/ (round (* 1000 seconds)) 1000) " s")
    (thread-sleep! seconds)))

;; Seeded at the first draw, not when loaded: the lab's address spaces are
;; forks of one loaded process (run-lab), and would share its seed.
(define backoff-random
  (let ((reals #f))
    (lambda ()
      (if (not reals)
          (let ((source (make-random-source)))
            (random-source-pseudo-randomize! source (current-process-id)
                                             (exact (floor (current-second))))
            (set! reals (random-source-make-reals source))))
      (reals))))
