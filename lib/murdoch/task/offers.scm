;;;; Offers: a robot freed offers itself to the tasks that wait for it,
;;;; best rank first (the robot's side), and a waiting task answers the
;;;; offers that come for it by a try (the poser's side).  waiting.scm
;;;; has the whole protocol.

;; The node's offering part: the offers this poser answers, and its
;; robot's offer rounds (a process drives at most one robot); each field
;; is described where it is used.
(define-record-type offering
  (make-offering offers round? again? lock waiters-here? new-waiters waiters-seen depth)
  offering?
  (offers offering-offers offering-offers-set!)
  (round? offering-round? offering-round?-set!)    ; an offer round runs here
  (again? offering-again? offering-again?-set!)    ; another was asked for since
  (lock offering-lock)
  (waiters-here? offering-waiters-here? offering-waiters-here?-set!)
  (new-waiters offering-new-waiters offering-new-waiters-set!)
  (waiters-seen offering-waiters-seen offering-waiters-seen-set!)
  (depth offering-depth offering-depth-set!))

(define-syntax the-offering (syntax-rules () ((_) (node-offering *node*))))

(define (open-offering!)
  (node-offering-set! (this-node)
                      (make-offering '() #f #f (make-mutex 'offers) #f #f #f offer-depth)))

;;; The poser's side

;;> What a freed robot \var{uid} calls where the tasks \var{ids} wait,
;;> best first: the first that may use it tries again at once.  Answers
;;> how many of ids it went through, to the one that tried, or all when
;;> each waits here no more or was offered robots already that could
;;> take every component this one could: one call for a poser's declines.
(define (receive-offer ids uid)
  (let loop ((ids ids) (n 1))
    (cond ((null? ids) (- n 1))
          ((offer-to-waiter! (car ids) uid) n)
          (else (loop (cdr ids) (+ n 1))))))

;; Offers robot uid to task id: #f if declined at once, else after its try.
(define (offer-to-waiter! id uid)
  (let* ((reply (make-mailbox))
         (offer (cons uid id))
         (w (with-lock (tasks-lock)
              (lambda ()
                (let ((w (find (lambda (w) (eq? (task-id (waiter-task w)) id))
                               (waiters))))
                  (and w (not (offered-enough? w uid))
                       (begin (update-offers! (lambda (os) (cons offer os))) w)))))))
    (and w
         (dynamic-wind
          (lambda () #f)
          (lambda ()
            (tell-waiter! w (list 'offer reply uid))
            (mailbox-take reply (+ (monotonic-seconds) (offer-seconds)) (lambda () #f))
            #t)
          (lambda ()
            (with-lock (tasks-lock)
              (lambda ()
                (update-offers! (lambda (os) (remove (lambda (o) (eq? o offer)) os))))))))))

;; Under (tasks-lock).
(define (update-offers! f)
  (let ((o (the-offering))) (offering-offers-set! o (f (offering-offers o)))))

;;> The (RANK POSER ID) of each task waiting here that may use robot
;;> \var{uid}, whose subjects are \var{subjects}: one it found capable
;;> when it last looked, or that has a component those subjects serve (a
;;> robot that joined since).  Best rank first, and only the first
;;> \var{limit} if given: a robot offers itself to the best first, and
;;> asks for more only when those all decline it, so that an offer round
;;> does not carry every waiting task of the lab.  Not one that the
;;> robots offered to it already serve, which would decline it.
(define (waiting-for uid . subjects+limit)
  (let ((subjects (and (pair? subjects+limit) (car subjects+limit)))
        (limit (and (pair? subjects+limit) (pair? (cdr subjects+limit))
                    (cadr subjects+limit))))
    (note-subjects! uid subjects)
    (with-lock (tasks-lock)
      (lambda ()
        (let loop ((ws (waiters)) (n 0) (out '()))
          (cond ((or (null? ws) (and limit (>= n limit))) (reverse out))
                ((and (wants? (car ws) uid subjects) (not (offered-enough? (car ws) uid)))
                 (loop (cdr ws) (+ n 1)
                       (cons (list (waiter-rank (car ws)) (local-aspace-uid)
                                   (task-id (waiter-task (car ws))))
                             out)))
                (else (loop (cdr ws) n out))))))))

;; How long a robot waits for the answer to its offer: the lab's timeout.
;; A waiter answers its offers after the try or look it is in, which on a
;; busy lab may take seconds; a robot that moved on sooner went to a
;; worse-ranked task meanwhile.
(define (offer-seconds) (setting 'timeout))

;; Whether robot uid would add nothing to the robots offered to w and not
;; held: with it, they could take, one each, no more of w's open
;; components than without, counted by kind, not number, so that of two
;; robots freed together the second goes on at once.  A robot that w won,
;; holding, in the try its offer began is no longer one of them, though
;; its offer is answered only when that try ends; nor is one that
;; another task's try here may take first.  Under (tasks-lock).
(define (offered-enough? w uid)
  (let* ((id (task-id (waiter-task w)))
         (held (held-uids w))
         (m (open-matching w (waiter-components w))))
    (for-each (lambda (o)
                (if (and (eq? (cdr o) id) (not (memq (car o) held))
                         (not (claimed-by-others? w (car o))))
                    (match! m (car o))))
              (offering-offers (the-offering)))
    (not (match! m uid))))

;; The offers being answered here, (UID . ID): the robot UID keeps itself
;; for this poser while task ID tries, and the poser's other waiting
;; tasks leave it alone meanwhile.

(define (offered-to-others w)
  (let ((id (task-id (waiter-task w))))
    (filter-map (lambda (o) (and (not (eq? (cdr o) id)) (car o)))
                (with-lock (tasks-lock) (lambda () (offering-offers (the-offering)))))))

;;; The robot's side: offers when its subjects are freed

;; Whether a task may wait for this robot (waiters-here?): set when a task
;; starts to wait anywhere, cleared by an offer round that finds none, so
;; that a lab where no task waits sends nothing more when a robot is freed.

;;> What a poser, \var{poser}, publishes to the lab when one of its tasks
;;> starts to wait, \var{rank} the best rank of those that did since its
;;> last note: the robots offer themselves when freed, and a free robot
;;> at once, since a task posed behind others waits for the offers.
(define (note-waiters! . poser+rank)
  (let* ((o (the-offering))
         (new (offering-new-waiters o)))
    (offering-waiters-here?-set! o #t)
    (offering-new-waiters-set! o (if (and (= 2 (length poser+rank)) (not (eq? new #t)))
                                     (better-rank (cadr poser+rank) new)
                                     #t)))
  (if (pair? poser+rank) (know-poser! (car poser+rank)))
  (if (and (robot-here?) (free-here?)) (offer-robot!))
  #t)

;; Each poser's (UID (WANTING ...)) for this robot, best depth first, of
;; every poser it knows: one whose note has not come yet may have a task
;; waiting before those of the poser that noted (docs/allocation.md).
(define (who-waits me depth)
  (ask-posers waiting-for me (subjects-here) depth))

;; Whether a task started to wait, or was reminded of, since this robot's
;; offer round asked who waits: the round's list may lack a better-ranked
;; task, and it asks again before its next offer.  The best rank of those
;; noted, or #t for one not known (a reminder): a round asks again only
;; if that rank goes before its next offer's, else with posers posing
;; non-stop it never gets past the lab's best task (docs/allocation.md).
;; This is new-waiters.
(define (ask-again-before? waiting)
  (let ((new (offering-new-waiters (the-offering))))
    (and new
         (or (eq? new #t) (null? waiting)
             (rank<? new (wanting-rank (car waiting)))))))

(define (robot-here?)
  (let ((a (lab-aspace-by-uid (current-lab) (local-aspace-uid))))
    (and a (lab-aspace-clause a 'capabilities) #t)))

;; Runs on every freeing of exclusive subjects here (the hook given to
;; open-subscriber!): starts an offer round, or asks the running one for
;; another.
(define (robot-freed!) (offer-robot!))

;; A running round keeps the robot as it is: a runner-up of the poser's
;; negotiation is freed while the robot waits for its answer, and the
;; task that tries must still find the robot its poser's.
(define (offer-robot!)
  (let ((o (the-offering)))
    (when (and (offering-waiters-here? o)
               (with-lock (offering-lock o)
                 (lambda ()
                   (if (offering-round? o)
                       (begin (offering-again?-set! o #t) #f)
                       (begin (offering-round?-set! o #t) #t)))))
      ;; At once, not in the round's thread, which may start late.
      (if (heard-of-waiters? o) (offer-subjects! 'nobody 3))
      (thread-start! (make-logged-thread offer-rounds 'offers)))))

;; The robot is kept for the poser it was last offered to until the
;; rounds end, so that no task takes it between two rounds.  A robot taken
;; meanwhile ends them: its next freeing starts a round.
(define (offer-rounds)
  (guard (e (#t (log-warn "offering this robot: " (error-message e))))
    (offer-round))
  (if (let ((o (the-offering)))
        (with-lock (offering-lock o)
          (lambda ()
            (let ((again (and (offering-again? o) (free-here?))))
              (offering-again?-set! o #f)
              (when (not again)
                (offer-subjects! #f)
                (offering-round?-set! o #f))
              again))))
      (offer-rounds)))

;; Offers this robot, while it is free, to the tasks that wait for it,
;; best rank first.  While one tries, only its poser may reserve here;
;; while it asks who waits, if tasks waited at its last round or one was
;; noted since, nobody may, so that no task takes it before the
;; best-ranked has been offered it.
;; In a lab where no task waits it refuses nobody, as in the thesis.
;; waiters-seen says whether tasks waited at its last round.

;; Each poser answers its best offer-depth tasks that may use the robot,
;; and the robot asks for twice as many when every one declined it, in
;; this round or the next, until it is taken: the best-ranked of the lab
;; are among them, and a round costs the same with 20 tasks waiting or
;; 2,000 (docs/allocation.md).  The depth asked for now is kept.
(define offer-depth 4)

(define (offer-round)
  (let* ((me (local-aspace-uid))
         (o (the-offering))
         (depth (offering-depth o))
         (keep? (heard-of-waiters? o)))
    (offering-waiters-here?-set! o #f)  ; a note after it stands
    (offering-new-waiters-set! o #f)
    (offer-subjects! (and keep? 'nobody) 3)
    (let* ((answers (run-logged (lambda () (who-waits me depth))
                                "who waits for this robot" '()))
           (waiting (list-sort (lambda (a b) (rank<? (wanting-rank a) (wanting-rank b)))
                               (append-map cadr answers))))
      (offering-waiters-seen-set! o (pair? waiting))
      (if (pair? waiting) (offering-waiters-here?-set! o #t))
      (offer-to me (within-horizon waiting answers depth))
      (cond ((not (free-here?)) (offering-depth-set! o offer-depth))
            ((any (lambda (a) (>= (length (cadr a)) depth)) answers)
             (offering-depth-set! o (* 2 depth))
             (if (not (offering-new-waiters o)) (offer-round)))))))

;; The entries of waiting that rank no later than the last of any poser's
;; answer of depth entries: that poser may have better ones past it.
(define (within-horizon waiting answers depth)
  (let ((horizon (fold (lambda (a h)
                         (if (>= (length (cadr a)) depth)
                             (better-rank (wanting-rank (last (cadr a))) h)
                             h))
                       #f answers)))
    (if horizon
        (take-while (lambda (e) (not (rank<? horizon (wanting-rank e)))) waiting)
        waiting)))

;; Whether tasks waited at the robot's last round or one was noted since:
;; not merely that it joined (offer-on-joining!), or a robot freed in a
;; lab where no task waits would refuse every negotiation while it asks.
(define (heard-of-waiters? o)
  (and (or (offering-waiters-seen o) (offering-new-waiters o)) #t))

;; How many of run a poser's answer n went through: a peer's word, checked.
(define (went-through n run)
  (if (exact-integer? n) (max 1 (min n (length run))) 1))

(define (offer-to me waiting)
  (when (and (pair? waiting) (free-here?))
    (let* ((poser (wanting-poser (car waiting)))
           (run (take-while (lambda (e) (eq? (wanting-poser e) poser)) waiting)))
      (offer-subjects! poser (+ (offer-seconds) 1))
      (let* ((n (guard (e (#t 1))
                  (parameterize ((remote-timeout (+ (offer-seconds) 1)))
                    (remote-apply (uid->aspace poser) receive-offer (map wanting-id run) me))))
             (left (list-tail waiting (went-through n run))))
        (if (and (ask-again-before? left) (free-here?))
            (let ((o (the-offering)))
              (with-lock (offering-lock o) (lambda () (offering-again?-set! o #t))))
            (offer-to me left))))))

;; The subjects this address space subscribes to: a poser matches them
;; against its waiting tasks' capabilities, for a robot it has not seen.
(define (subjects-here) (map car (subscription-statuses '>)))

;;> What an address space does once it has joined the lab: a robot
;;> offers itself at once to the tasks that wait for it, which may have
;;> waited for it while it was away, or before it came.
(define (offer-on-joining!)
  (offering-waiters-here?-set! (the-offering) #t)
  (if (and (robot-here?) (free-here?)) (robot-freed!)))

;; Whether no subject here is held exclusively.
(define (free-here?)
  (every (lambda (s) (memq (cadr s) '(() shared))) (subscription-statuses '>)))
