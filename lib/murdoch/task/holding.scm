;;;; Holding and giving way: what a task holds while it waits (the
;;;; thesis's chapter 6 wish)
;;
;; A task started with hold #t keeps, while it waits, the robots it won
;; for some of its components, and waits for the others.  No deadlock:
;; a waiting task gives up what it holds when a better-ranked waiting
;; task could start with it (give-way!), and ranks are totally ordered,
;; so the best-ranked waiting task never waits on one that holds; a
;; running component is never taken away.  docs/allocation.md gives the
;; argument.

;; Frees a winner of a negotiation: a runner-up, a task cancelled, or
;; a robot held and given up.
(define (free-winner! winner type)
  (if (eq? type 'exclusive)
      (guard (e (#t #f)) ((winner-promise winner) #f))))

;; A try that keeps what it wins: each component of w not yet held is
;; negotiated alone, without the robots held or given way on, those with
;; the fewest capable robots first (a component that accepts two kinds
;; took the one robot of the kind its neighbour alone accepts), then in
;; priority order, and without the robots offered that a largest
;; matching of them gives to the others (offered-matching).  Answers
;; (winners type-list) once every component has a robot.
(define (hold-try w priorities)
  (let* ((t (waiter-task w)) (cs (waiter-components w))
         (order (fewest-capable-first w cs priorities))
         (m (offered-matching w order)))
    (for-each
     (lambda (c)
       (let ((excluded (append (left-out w) (matched-to-others m c))))
         (if (and (not (assv (component-index c) (waiter-held w)))
                  (may-win? w c excluded))
             (let ((team (parameterize ((pose-task-excluded excluded))
                           (negotiate (task-name t) 1 (list (component-capabilities c))
                                      (list (component-metric c))
                                      (list (component-proc c))))))
               (if (pair? team)
                   (waiter-held-set! w (cons (list (component-index c)
                                                   (car (negotiated-winners team))
                                                   (car (negotiated-types team)))
                                             (waiter-held w))))))))
     order)
    (let ((held (map (lambda (c) (assv (component-index c) (waiter-held w))) cs)))
      (cond ((every pair? held)
             (waiter-held-set! w '())
             (list (map held-winner held) (map held-type held)))
            (else 'not-enough-takers)))))

;; w's components cs, the fewest capable robots first, then by priority.
(define (fewest-capable-first w cs priorities)
  (map cdr (list-sort (lambda (a b)
                        (let ((na (capable-count w (cdr a))) (nb (capable-count w (cdr b))))
                          (or (< na nb) (and (= na nb) (> (car a) (car b))))))
                      (map cons priorities cs))))

;; The robots offered to w's try, not held nor excluded, matched to its
;; open components in order: as offered-enough? counted on (docs/allocation.md).
(define (offered-matching w order)
  (let ((m (open-matching w order))
        (out (left-out w)))
    (for-each (lambda (uid) (if (not (memq uid out)) (match! m uid)))
              (waiter-offered w))
    m))

;; The robots no negotiation of w's takes: held, given way on, or excluded.
(define (left-out w)
  (append (held-uids w) (waiter-yielded w) (pose-task-excluded)))

;; How many robots w's last look found capable of c; before it, as many
;; as the lab has.
(define (capable-count w c)
  (length (or (looked-capable w c) (lab-aspaces (current-lab)))))

;; Frees a robot that w holds for one component and that another, which
;; no other capable robot serves, needs: that one waits on w itself, and
;; with every robot of the lab held no robot is freed to offer itself
;; (tasks of components (ab ab b), holding both b robots for the two ab,
;; stalled a lab).  The robot given up is that of the component with the
;; most capable robots, among those with one w does not hold; freed, it
;; offers itself, and hold-try gives it to the fewer first.
(define (unblock! w)
  (let ((movable (movable-for-blocked w)))
    (when (pair? movable)
      (let* ((c (fold (lambda (c best)
                        (if (> (capable-count w c) (capable-count w best)) c best))
                      (car movable) (cdr movable)))
             (uid (held-uid (assv (component-index c) (waiter-held w)))))
        (progress (task-id (waiter-task w)) ": gives up " uid " of component "
                  (component-index c) " for another that only it serves")
        (let-go-held! w uid)))))

;;> Whether waiting task \var{w} waits on itself, unblock! freeing one of
;;> its robots.
(define (blocked-on-itself? w) (pair? (movable-for-blocked w)))

;; The components of w holding a robot that a component of w not held
;; needs, every robot capable of that one being w's, and that have a
;; capable robot w does not hold.
(define (movable-for-blocked w)
  (let* ((held-by (lambda (c) (assv (component-index c) (waiter-held w))))
         (capable (lambda (c) (or (looked-capable w c) '())))
         (own (held-uids w))
         (blocked (find (lambda (c)
                          (and (not (held-by c)) (pair? (capable c))
                               (every (lambda (uid) (memq uid own)) (capable c))))
                        (waiter-components w))))
    (if blocked
        (filter (lambda (c)
                  (let ((h (held-by c)))
                    (and h (memq (held-uid h) (capable blocked))
                         (any (lambda (uid) (not (memq uid own))) (capable c)))))
                (waiter-components w))
        '())))

;; Whether a negotiation of c, with the robots excluded left out, may
;; find a robot: one of those its last look found capable of it, or one
;; offered that the look did not know (a robot that joined since).  A
;; robot offers itself to a task of four components, and negotiating the
;; three it cannot take cost a round of the lab each, with the poser's
;; other tries waiting.
(define (may-win? w c excluded)
  (let ((capable (looked-capable w c))
        (free? (lambda (uid) (not (memq uid excluded)))))
    (or (not capable)
        (any free? capable)
        (any (lambda (uid) (and (free? uid) (not (memq uid (waiter-capable w)))))
             (waiter-offered w)))))

;; Frees what w holds on robot uid, or on every robot.
(define (let-go-held! w . uid)
  (let ((out (filter (lambda (h) (or (null? uid) (eq? (held-uid h) (car uid))))
                     (waiter-held w))))
    (for-each (lambda (h) (free-winner! (held-winner h) (held-type h))) out)
    (waiter-held-set! w (remove (lambda (h) (memq h out)) (waiter-held w)))))

;; Holds what w holds for another lease.
(define (keep-held! w)
  (waiter-kept-set! w (monotonic-seconds))
  (for-each (lambda (h)
              (if (eq? (held-type h) 'exclusive)
                  (if (not (guard (e (#t #f)) ((winner-promise (held-winner h)) 'keep)))
                      (let-go-held! w (held-uid h)))))
            (waiter-held w)))

;; Acts on the news: gives way on each robot a better-ranked task asked
;; for, and takes robots offered to it again.
(define (give-way! w news)
  (for-each
   (lambda (n)
     (case (news-kind n)
       ((give-way)
        (let ((uid (give-way-uid n)))
          (when (memq uid (held-uids w))
            (progress (task-id (waiter-task w)) ": gives way on " uid)
            (let-go-held! w uid)
            (waiter-yielded-set! w (cons uid (waiter-yielded w))))))
       ((offer)
        (waiter-yielded-set! w (remove (lambda (u) (eq? u (offer-uid n)))
                                       (waiter-yielded w))))))
   news))

;;> What a waiting task of rank \var{rank} calls where the task that holds
;;> robot \var{uid} waits: that task gives way on it if \var{rank} goes
;;> before its own.  Answers #t.
(define (receive-give-way uid rank)
  (for-each (lambda (w)
              (if (and (memq uid (held-uids w)) (rank<? rank (waiter-rank w)))
                  (tell-waiter! w (list 'give-way uid))))
            (with-lock (tasks-lock) waiters))
  #t)

;; Asks the waiting tasks that rank after w, worse, and hold robots w
;; could start with, to give way, when with those robots and the free
;; ones each of w's components not held would have one.  A look asks it
;; of each of its poser's hundreds of tasks: it first looks for a held
;; robot that w could use at all.
(define (ask-way! w lines worse)
  (let* ((yieldable (append-map waiting-there-held worse))
         (mine (held-uids w))
         (open (filter-map (lambda (c line)
                             (and (not (assv (component-index c) (waiter-held w))) line))
                           (waiter-components w) lines))
         (wanted (filter (lambda (uid)
                           (any (lambda (line) (memq uid (explanation-capable line))) open))
                         yieldable)))
    (when (and (pair? wanted) (startable? open wanted mine))
      (for-each (lambda (o)
                  (for-each (lambda (uid)
                              (if (memq uid wanted)
                                  (guard (e (#t #f))
                                    (remote-apply (uid->aspace (waiting-there-poser o))
                                                  receive-give-way uid (waiter-rank w)))))
                            (waiting-there-held o)))
                worse))))

;; Whether each of the open components' explanations has a robot, free or
;; wanted from a worse task, not w's own (mine), and they have as many in
;; all as they are.
(define (startable? open wanted mine)
  (let ((candidates (map (lambda (line)
                           (filter (lambda (uid)
                                     (and (not (memq uid mine))
                                          (memq uid (explanation-capable line))))
                                   (append (explanation-free line) wanted)))
                         open)))
    (and (every pair? candidates)
         (>= (length (delete-duplicates (apply append candidates))) (length open)))))
