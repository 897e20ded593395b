;;;; Waiting and rank: how a task waits its turn (its turn record, read
;;;; from start-task's keywords), the order of the lab's waiting tasks
;;;; (their ranks) and each one's place in it, and the record of a task
;;;; waiting here (its waiter), with the news that comes for it.  The
;;;; waiting itself is waiting.scm's; docs/tasks.md tells it.

(define-record-type turn
  (make-turn wait? hold? priority deadline posed)
  turn?
  (wait? turn-wait?)
  (hold? turn-hold?)
  (priority turn-priority)
  (deadline turn-deadline)              ; monotonic-seconds, or #f
  (posed turn-posed))                   ; utc-seconds

;; A turn from start-task's keywords and their values.
(define (read-turn who options)
  (let loop ((kv options)
             (wait (eq? (setting 'when-robots-busy) 'wait))
             (hold #f)
             (priority (pose-task-priority))
             (deadline #f))
    (define (bad what)
      (error (string-append who ": " what) kv))
    (define (value ok? what)
      (if (not (ok? (cadr kv))) (bad what))
      (cadr kv))
    (define (at-least-0? x) (and (real? x) (>= x 0)))
    (cond
     ((null? kv)
      (make-turn (or wait hold) hold priority
                 (and deadline (+ (monotonic-seconds) deadline)) (utc-seconds)))
     ((not (and (symbol? (car kv)) (pair? (cdr kv))))
      (bad (string-append "after the lists come keywords, each with its value: "
                          "wait, hold, priority, deadline")))
     ((eq? (car kv) 'wait)
      (loop (cddr kv) (value boolean? "wait is #t or #f") hold priority deadline))
     ((eq? (car kv) 'hold)
      (loop (cddr kv) wait (value boolean? "hold is #t or #f") priority deadline))
     ((eq? (car kv) 'priority)
      (loop (cddr kv) wait hold (value at-least-0? "priority is a number, 0 or more")
            deadline))
     ((eq? (car kv) 'deadline)
      (loop (cddr kv) wait hold priority
            (value at-least-0? "deadline is a number of seconds, 0 or more")))
     (else (bad "no such option; the options are wait, hold, priority and deadline")))))

;; Refuses a task that would wait when this address space has
;; max-waiting tasks waiting or about to.  Under (tasks-lock).
(define (check-waiting-room turn)
  (if (and turn (turn-wait? turn)
           (>= (count (lambda (t) (and (task-turn t) (turn-wait? (task-turn t))
                                       (memq (task-state t) '(negotiating waiting holding))))
                      (posed-tasks))
               (setting 'max-waiting)))
      (error "start-task: this address space has max-waiting tasks waiting already"
             (setting 'max-waiting))))

(define (turn-rank turn id)
  (list (- (turn-priority turn) (* (setting 'aging) (turn-posed turn)))
        (turn-posed turn) (symbol->string id)))

;; The parts of a rank, (SCORE POSED ID) as turn-rank makes it: it travels
;; to the other posers.
(define (rank-score r) (car r))
(define (rank-posed r) (cadr r))
(define (rank-id r) (car (cddr r)))

;; Whether rank a goes before rank b.
(define (rank<? a b)
  (or (> (rank-score a) (rank-score b))
      (and (= (rank-score a) (rank-score b))
           (or (< (rank-posed a) (rank-posed b))
               (and (= (rank-posed a) (rank-posed b))
                    (string<? (rank-id a) (rank-id b)))))))

;; Seconds between a poser's looks at its waiting tasks, and between a
;; robot's asks of the whole lab who waits: ten heartbeats, or a third of
;; the lease if that is sooner, so a look comes before a held robot's
;; lease runs out.
(define (look-period)
  (min (* 10 (setting 'heartbeat))
       (/ (setting 'lease) 3)))

;; The better of ranks a and b, either #f for none.
(define (better-rank a b)
  (cond ((not a) b) ((not b) a) ((rank<? a b) a) (else b)))

;; A task waiting here: news is what came for it, offers and cancels, and
;; bell rings when news comes.
(define-record-type waiter
  (make-waiter task components rank)
  waiter?
  (task waiter-task)
  (components waiter-components)
  (rank waiter-rank)
  (held waiter-held waiter-held-set!)            ; ((INDEX WINNER TYPE) ...)
  (looked waiter-looked waiter-looked-set!)      ; monotonic-seconds
  (kept waiter-kept waiter-kept-set!)            ; monotonic-seconds
  (yielded waiter-yielded waiter-yielded-set!)   ; robots it gave way on
  (capable waiter-capable waiter-capable-set!)   ; uids of its capable robots, or #t
  (capables waiter-capables waiter-capables-set!) ; ((COMPONENT UID ...) ...), or ()
  (offered waiter-offered waiter-offered-set!)   ; the uids offered to its try
  (position waiter-position waiter-position-set!)
  (why waiter-why waiter-why-set!)               ; a line a component
  (never waiter-never waiter-never-set!)         ; why it never can start, or #f
  (excluded waiter-excluded waiter-excluded-set!) ; its pose-task-excluded
  (news waiter-news waiter-news-set!)
  (bell waiter-bell waiter-bell-set!))

;; The uids w's last look found capable of its component c, or #f before
;; one.
(define (looked-capable w c)
  (let ((cc (assq c (waiter-capables w))))
    (and cc (cdr cc))))

;; Of robots to w's components open, one each; taken is by open's index.
(define-record-type matching
  (make-matching waiter open taken)
  matching?
  (waiter matching-waiter)
  (open matching-open)
  (taken matching-taken))

;;> An empty matching of robots to those of components \var{cs} of
;;> waiting task \var{w} not held, which match! grows, giving each robot
;;> to the first it fits.
(define (open-matching w cs)
  (let ((open (list->vector (remove (lambda (c) (assv (component-index c) (waiter-held w)))
                                    cs))))
    (make-matching w open (make-vector (vector-length open) #f))))

;;> Whether robot \var{uid} can take one more of \var{m}'s components
;;> (by the last look), moving those taken on along an augmenting path;
;;> if so, it does: robots added so take the most (docs/allocation.md).
(define (match! m uid)
  (let* ((open (matching-open m))
         (taken (matching-taken m))
         (seen (make-vector (vector-length open) #f))
         (fits? (lambda (uid i)
                  (let ((capable (looked-capable (matching-waiter m) (vector-ref open i))))
                    (if capable
                        (memq uid capable)
                        (subjects-fit? uid (vector-ref open i)))))))
    (let take ((uid uid))
      (let loop ((i 0))
        (cond ((= i (vector-length open)) #f)
              ((and (not (vector-ref seen i)) (fits? uid i))
               (vector-set! seen i #t)
               (if (or (not (vector-ref taken i)) (take (vector-ref taken i)))
                   (begin (vector-set! taken i uid) #t)
                   (loop (+ i 1))))
              (else (loop (+ i 1))))))))

;; Global: the subjects of each robot that asked who waits here, ((UID
;; . SUBJECTS) ...), replaced whole: before a task's first look, a robot
;; offered fits a component whose subjects it has, not any.  Offered
;; robots that fitted none of a task in the burst were counted as enough,
;; and the robots it needed declined (docs/allocation.md).
(define *robot-subjects* '())

;;> Notes that robot \var{uid} subscribes to \var{subjects}.
(define (note-subjects! uid subjects)
  (let ((known (assq uid *robot-subjects*)))
    (if (and (list? subjects) (every symbol? subjects)   ; a peer's word, checked
             (not (and known (equal? (cdr known) subjects))))
        (set! *robot-subjects*
              (cons (cons uid subjects)
                    (remove (lambda (e) (eq? (car e) uid)) *robot-subjects*))))))

;; Whether robot uid has every subject of component c; #t if not known.
(define (subjects-fit? uid c)
  (let ((known (assq uid *robot-subjects*)))
    (or (not known) (has-subjects? (cdr known) c))))

(define (has-subjects? subjects c)
  (every (lambda (s) (memq s subjects))
         (apply append (capability-layout (component-capabilities c)))))

;;> The uids \var{m} gives to the components but \var{c}, where the last
;;> look said they fit.  Before a look a robot goes to the first component
;;> by guess, and a try that kept it from the one it fits took none.
(define (matched-to-others m c)
  (let loop ((i 0) (out '()))
    (cond ((= i (vector-length (matching-open m))) out)
          ((and (vector-ref (matching-taken m) i)
                (not (eq? c (vector-ref (matching-open m) i)))
                (looked-capable (matching-waiter m) (vector-ref (matching-open m) i)))
           (loop (+ i 1) (cons (vector-ref (matching-taken m) i) out)))
          (else (loop (+ i 1) out)))))

;; The node's line part: the tasks waiting here, best rank first, under
;; (tasks-lock); the posers known to have tasks waiting, and when the lab
;; was last asked for them; the other posers' waiting tasks as last asked
;; (others-waiting, below).
(define-record-type line
  (make-line waiters tries-running tries-waiting posers posers-asked others)
  line?
  (waiters line-waiters line-waiters-set!)
  (tries-running line-tries-running line-tries-running-set!) ; their try-turns
  (tries-waiting line-tries-waiting line-tries-waiting-set!) ; best first
  (posers line-posers line-posers-set!)
  (posers-asked line-posers-asked line-posers-asked-set!)
  (others line-others line-others-set!))

(define-syntax the-line (syntax-rules () ((_) (node-line *node*))))

(define (open-line!) (node-line-set! (this-node) (make-line '() '() '() '() #f #f)))

(define (waiters) (line-waiters (the-line)))
(define (add-waiter! w)
  (line-waiters-set! (the-line) (in-rank-order w (waiters) waiter-rank)))

;;> \var{ls}, best rank first by \var{rank-of}, with \var{x} after its equals.
(define (in-rank-order x ls rank-of)
  (let-values (((before after)
                (break (lambda (y) (rank<? (rank-of x) (rank-of y))) ls)))
    (append before (cons x after))))
(define (drop-waiter! w)
  (line-waiters-set! (the-line) (remove (lambda (x) (eq? x w)) (waiters))))

;; News, read by name: (first), try at once; (cancel); (give-way UID); (offer REPLY UID).
(define (news-kind n) (car n))
(define (offer? n) (eq? (news-kind n) 'offer))
(define (offer-reply n) (cadr n))
(define (offer-uid n) (car (cddr n)))
(define (give-way-uid n) (cadr n))

(define (tell-waiter! w news)
  (with-lock (tasks-lock)
    (lambda ()
      (cond ((memq w (line-waiters (the-line)))
             (waiter-news-set! w (cons news (waiter-news w)))
             (mailbox-put! (waiter-bell w) #t))
            ((offer? news) (answer-offers! (list news) #f))))))

;; The news that came for w, oldest first, once some has come or the
;; monotonic second until has passed.
(define (take-news! w until)
  (mailbox-take (waiter-bell w) until (lambda () #f))
  (with-lock (tasks-lock)
    (lambda ()
      (let ((news (reverse (waiter-news w))))
        (waiter-news-set! w '())
        (waiter-bell-set! w (make-mailbox))
        news))))

;; What w holds of a component, (INDEX WINNER TYPE), read by name.
(define (held-index h) (car h))
(define (held-winner h) (cadr h))
(define (held-type h) (car (cddr h)))
(define (held-uid h) (winner-uid (held-winner h)))

(define (held-uids w) (map held-uid (waiter-held w)))

;;> The lab's line, as place-in-line reads it: the other posers' ranks in
;;> order, as waiting-at-others last asked for them, and this poser's own,
;;> as its waiters keep them; neither sorted at a look (docs/allocation.md).
(define-record-type line-ranks
  (make-line-ranks others own)
  line-ranks?
  (others line-ranks-others)
  (own line-ranks-own))

;; Logged, not silent, when the lab cannot be asked: docs/allocation.md.
(define (line-ranks-now)
  (make-line-ranks (run-logged (lambda () (others-waiting-line (others-waiting)))
                               "the other posers' line" (vector))
                   (list->vector (map waiter-rank (with-lock (tasks-lock) waiters)))))

(define (line-ranks-length line)
  (+ (vector-length (line-ranks-others line)) (vector-length (line-ranks-own line))))

;; w's place in the lab's line, line as line-ranks-now makes it: 1 + how
;; many rank before it.  One order for the whole lab, 1 to n, whatever
;; robots each may use.
(define (place-in-line w line)
  (+ 1
     (ranked-before (line-ranks-others line) (waiter-rank w))
     (ranked-before (line-ranks-own line) (waiter-rank w))))

;; How many of ranks, a vector in rank order, go before rank: by halving.
(define (ranked-before ranks rank)
  (let loop ((lo 0) (hi (vector-length ranks)))
    (if (= lo hi)
        lo
        (let ((mid (quotient (+ lo hi) 2)))
          (if (rank<? (vector-ref ranks mid) rank)
              (loop (+ mid 1) hi)
              (loop lo mid))))))

;;> The (RANK HELD) of each task waiting here: its rank, and the uids of
;;> the robots it holds; only of those that hold one if \var{holding} is
;;> given and true.  The robots each may use stay here: a line of 2,000
;;> tasks that carried them was megabytes a second.
(define (waiting-ranks . holding)
  (filter-map (lambda (w)
                (let ((held (held-uids w)))
                  (and (or (null? holding) (not (car holding)) (pair? held))
                       (list (waiter-rank w) held))))
              (with-lock (tasks-lock) waiters)))

;; A task that waits at poser, as its entry of waiting-ranks says.
(define-record-type waiting-there
  (make-waiting-there poser rank held)
  waiting-there?
  (poser waiting-there-poser)
  (rank waiting-there-rank)
  (held waiting-there-held))

;; Every task of the lab that waits, each a waiting-there, or only those
;; holding robots if holding is given and true, as waiting-ranks has it;
;; ask-posers answers (POSER ENTRIES) for each poser.
(define (waiting-elsewhere . holding)
  (append-map (lambda (answer)
                (map (lambda (e) (apply make-waiting-there (car answer) e))
                     (cadr answer)))
              (apply ask-posers waiting-ranks holding)))

;; The posers that may have tasks waiting, as this address space knows
;; them: those that said so (note-waiters!, published to the whole lab),
;; and those subscribed to waiting-tasks when it last asked the whole lab,
;; which it does every look-period, so that a poser it missed (one that
;; joined later) is found: asking every address space each round cost
;; the robots most of their CPU (docs/speed.md).  A poser heard of while
;; the first ask went is kept: its note may be the last.

;;> Notes that poser \var{uid} has tasks waiting.
(define (know-poser! uid)
  (let ((posers (line-posers (the-line))))
    (if (not (memq uid posers))
        (line-posers-set! (the-line) (cons uid posers)))))

(define (ask-lab-due?)
  (or (not (line-posers-asked (the-line)))
      (> (- (monotonic-seconds) (line-posers-asked (the-line))) (look-period))))

;;> What request of waiting-tasks answers, \var{proc} applied to
;;> \var{args} by each poser with tasks waiting, ((UID VALUE) ...), asked
;;> of the posers known to have some, of the whole lab every look-period.
(define (ask-posers proc . args)
  (if (ask-lab-due?)
      (let ((answers (apply request 'waiting-tasks proc args)))
        (line-posers-set! (the-line)
                          (delete-duplicates (append (map car answers)
                                                     (line-posers (the-line)))))
        (line-posers-asked-set! (the-line) (monotonic-seconds))
        answers)
      (apply ask-these-posers (line-posers (the-line)) proc args)))

;;> The same, asked of the posers \var{posers} alone.
(define (ask-these-posers posers proc . args)
  (filter-map (lambda (o) (and (outcome-ok? o) (list (outcome-uid o) (outcome-value o))))
              (apply remote-apply-all (filter-map live-aspace posers) proc args)))

;; The other posers' waiting tasks as last asked, under (tasks-lock): when
;; (monotonic-seconds), the waiting-theres, and their ranks sorted once.
(define-record-type others-waiting-answer   ; others-waiting is the procedure
  (make-others-waiting asked entries line)
  others-waiting?
  (asked others-waiting-asked)
  (entries others-waiting-entries)
  (line others-waiting-line))

;; The waiting tasks of the other posers, as waiting-elsewhere answers,
;; asked of the lab at most once a heartbeat for every 100 tasks it
;; waited last time, and not before since, if given (docs/allocation.md).
;; A place may so be W/100 heartbeats old for tasks posed elsewhere; who
;; is offered a robot is decided by the robot's own round, never by this.
(define (others-waiting . since)
  (let ((cached (with-lock (tasks-lock) (lambda () (line-others (the-line))))))
    (if (and cached
             (or (null? since) (>= (others-waiting-asked cached) (car since)))
             (< (- (monotonic-seconds) (others-waiting-asked cached))
                (* (setting 'heartbeat)
                   (max 1 (/ (vector-length (others-waiting-line cached)) 100)))))
        cached
        (let* ((asked (monotonic-seconds))
               (me (local-aspace-uid))
               (entries (remove (lambda (o) (eq? (waiting-there-poser o) me))
                                (waiting-elsewhere)))
               (fresh (make-others-waiting asked entries
                                           (list->vector
                                            (list-sort rank<? (map waiting-there-rank entries))))))
          (with-lock (tasks-lock) (lambda () (line-others-set! (the-line) fresh)))
          fresh))))

;;> The waiting tasks of the other posers, as waiting-elsewhere answers,
;;> asked no earlier than monotonic second \var{since}.
(define (waiting-at-others since) (others-waiting-entries (others-waiting since)))

;; Every task of the lab that waits holding robots, asked afresh: no more
;; of them than robots.
(define (lab-holders) (waiting-elsewhere #t))

;;> Whether waiter \var{w} may use robot \var{uid}, subscribed to
;;> \var{subjects} (or #f): for a component it does not hold, when its
;;> look found uid capable; else, a robot its look did not know or before
;;> it looked, when subjects serve such a component.
(define (wants? w uid subjects)
  (let ((capable (waiter-capable w)))
    (cond ((eq? capable #t) (or (not subjects) (serves? subjects w)))
          ((memq uid capable)
           (any (lambda (cc)
                  (and (not (assv (component-index (car cc)) (waiter-held w)))
                       (memq uid (cdr cc))))
                (waiter-capables w)))
          (else (and subjects (serves? subjects w))))))

;; Whether a robot subscribed to subjects could take a component of w
;; that w does not hold: one offered for a component held was declined by
;; the try, and went to a worse-ranked task meanwhile.
(define (serves? subjects w)
  (any (lambda (c)
         (and (not (assv (component-index c) (waiter-held w)))
              (has-subjects? subjects c)))
       (waiter-components w)))

;;> Each task waiting here, as (RANK . ENTRY), ENTRY as (tasks) lists it:
;;> the lab's status and its view number them all, from their ranks, in
;;> one line.
(define (waiting-entries)
  (map (lambda (w) (cons (waiter-rank w) (waiting-entry w)))
       (with-lock (tasks-lock) waiters)))

;; w as (tasks) lists it: (posed ID STATE WHY PLACE PRIORITY HELD WANTS).
(define (waiting-entry w)
  (let ((t (waiter-task w)))
    (list 'posed (task-id t) (task-state t) (waiter-why w) (waiter-position w)
          (turn-priority (task-turn t)) (held-uids w)
          (filter-map (lambda (c)
                        (and (not (assv (component-index c) (waiter-held w)))
                             (component-capabilities c)))
                      (waiter-components w)))))

;; The parts of an entry of waiting-for, from any poser of the lab.
(define (wanting-rank e) (car e))
(define (wanting-poser e) (cadr e))
(define (wanting-id e) (car (cddr e)))
(define (answer-offers! offers took?)
  (for-each (lambda (offer) (mailbox-put! (offer-reply offer) took?)) offers))
