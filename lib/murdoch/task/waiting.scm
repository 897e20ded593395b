;;;; Tasks that wait their turn (thesis ch. 6; docs/tasks.md)
;;
;; A task started with wait #t that finds too few capable robots free
;; waits, trying only when a robot offers itself, while its poser
;; subscribes to waiting-tasks and tells the lab (note-waiters!).  A robot
;; freed (robot-freed!) asks who waits for it and offers itself to each
;; in rank order (offers.scm) until one starts.  A rank (rank.scm) is a
;; total order, the same everywhere, that aging does not reshuffle.  A
;; poser looks at the lab once for all its waiting tasks (look-all!), and
;; a task whose capable robots are all gone fails at the next look.
;; docs/tasks.md tells it all.

(define (enlist! w)
  (waiter-held-set! w '())
  (waiter-looked-set! w #f)
  (waiter-kept-set! w (monotonic-seconds))
  (waiter-yielded-set! w '())
  (waiter-capable-set! w #t)            ; any robot, until it has looked
  (waiter-capables-set! w '())
  (waiter-offered-set! w '())
  (waiter-position-set! w #f)
  (waiter-why-set! w '())
  (waiter-never-set! w #f)
  (waiter-excluded-set! w (pose-task-excluded))
  (waiter-news-set! w '())
  (waiter-bell-set! w (make-mailbox))
  (with-lock (tasks-lock)
    (lambda ()
      (task-waiter-set! (waiter-task w) w)
      (add-waiter! w)
      (known-capable! w)
      (start-looker!)
      (subscribe 'waiting-tasks)))
  (note-lab! (waiter-rank w)))

;; The node's looking part: a poser's one line of tasks, and what its
;; notes to the lab and its one looking thread share.
(define-record-type looking
  (make-looking noting? note-again looker? bell takers free-seen turn)
  looking?
  (noting? looking-noting? looking-noting?-set!)    ; a publication goes
  (note-again looking-note-again looking-note-again-set!) ; best rank since, or #f
  (looker? looking-looker? looking-looker?-set!)    ; the looking thread runs
  (bell looking-bell)                   ; rung by a task that wants a look
  (takers looking-takers looking-takers-set!)
  (free-seen looking-free-seen looking-free-seen-set!)
  (turn looking-turn looking-turn-set!))          ; where the next look's rest begins

(define-syntax the-looking (syntax-rules () ((_) (node-looking *node*))))

(define (open-looking!)
  (node-looking-set! (this-node)
                     (make-looking #f #f #f (make-mailbox) #f '() 0)))

;; Tells the lab that a task of rank rank waits here: once for all the
;; tasks that start to wait while the publication goes, with the best of
;; their ranks, from a thread of its own: a task publishing for the
;; others answered no offer meanwhile (docs/allocation.md).
(define (note-lab! rank)
  (when (with-lock (tasks-lock)
          (lambda ()
            (let ((l (the-looking)))
              (if (looking-noting? l)
                  (begin (looking-note-again-set! l (better-rank rank (looking-note-again l)))
                         #f)
                  (begin (looking-noting?-set! l #t) #t)))))
    (thread-start! (make-logged-thread (lambda () (publish-notes! rank)) 'notes))))

(define (publish-notes! rank)
  (let loop ((rank rank))
    (guard (e (#t (log-warn "telling the lab a task waits: " (error-message e))))
      (publish 'all note-waiters! (local-aspace-uid) rank))
    (let ((again (with-lock (tasks-lock)
                   (lambda ()
                     (let ((again (looking-note-again (the-looking))))
                       (looking-note-again-set! (the-looking) #f)
                       (if (not again) (looking-noting?-set! (the-looking) #f))
                       again)))))
      (if again (loop again)))))

;; The offers w had not answered are declined: a robot waits for no task
;; that no longer waits.
(define (delist! w)
  (with-lock (tasks-lock)
    (lambda ()
      (task-waiter-set! (waiter-task w) #f)
      (drop-waiter! w)
      (answer-offers! (filter offer? (waiter-news w)) #f)
      (waiter-news-set! w '())
      (if (null? (waiters)) (unsubscribe 'waiting-tasks)))))


;; What try, a procedure of the task's waiter that negotiates cs of t,
;; answers; for a task that waits, tried again whenever a robot it may
;; use is offered, until it wins its robots or cannot: (winners
;; type-list), or a symbol, not-enough-takers, deadline or cancelled.
(define (negotiate-turn t cs try)
  (let ((w (make-waiter t cs (turn-rank (task-turn t) (task-id t)))))
    (if (not (turn-wait? (task-turn t)))
        (try w)
        (dynamic-wind
         (lambda () (enlist! w) (check-first! w))
         (lambda () (wait-turn w try '()))
         (lambda () (let-go-held! w) (delist! w))))))

;; Tries, answers the offers that woke it, and waits for the next.  It
;; tries only when a robot offered itself, or when it was posed with no
;; better-ranked task waiting in the lab: a robot's offers
;; come in rank order, and a try out of turn could take a robot freed for
;; a better-ranked task.  It asks its poser to look at the lab again when
;; what it holds changed, or a second after its last look: an offer is
;; answered by one try.
(define (wait-turn w try news)
  (let ((t (waiter-task w))
        (offers (filter offer? news))
        (held (held-uids w)))
    (give-way! w news)
    (unblock! w)
    (cond
     ((eq? (task-state t) 'cancelled) (answer-offers! offers #f) 'cancelled)
     ((eq? (task-state t) 'let-go) (answer-offers! offers #f) 'let-go)
     ((past? (turn-deadline (task-turn t))) (answer-offers! offers #f) 'deadline)
     (else
      (let ((team (if (or (pair? offers)
                          (assq 'first news))
                      (try-in-turn w try (map offer-uid offers))
                      'not-enough-takers)))
        (answer-offers! offers (pair? team))
        (cond
         ((pair? team) team)
         ((waiter-never w)
          => (lambda (never)
               (for-each (lambda (c) (component-state-set! c (list 'failed never)))
                         (waiter-components w))
               'not-enough-takers))
         (else
          (if (or (not (equal? held (held-uids w))) (look-due? w)) (want-look!))
          (if (> (- (monotonic-seconds) (waiter-kept w))
                 (/ (setting 'lease) 4))
              (keep-held! w))
          (wait-turn w try
                     (take-news! w (next-look (turn-deadline (task-turn t))))))))))))

;; One try of w's, in turn with this poser's tries that may ask the same
;; robots (docs/allocation.md).  It leaves alone the robots offered to
;; the others, and all but offered when w takes robots one at a time: a
;; robot may be kept for this poser on its way to another of its tasks.

(define (try-in-turn w try offered)
  (let ((claim (try-claim w offered)))
    (in-try-turn (make-try-turn w claim (make-mailbox))
      (lambda ()
        (waiter-offered-set! w offered)
        (let ((excluded (append (offered-to-others w) (not-offered w offered)
                                (pose-task-excluded))))
          (quiet-try (lambda ()
                       (parameterize ((pose-task-excluded excluded)
                                      (request-audience (audience claim excluded)))
                         (try w)))))))))

;; Runs thunk once let-in lets turn in; a thread that leaves while it
;; waits (cancelled, abandoned) leaves the queue.
(define (in-try-turn turn thunk)
  (dynamic-wind
   (lambda () (join-try-turns! turn))
   (lambda ()
     (let wait ()
       (if (not (mailbox-take (try-turn-bell turn) (+ (monotonic-seconds) 60) (lambda () #f)))
           (wait)))
     (thunk))
   (lambda () (leave-try-turns! turn))))

;; The robots w's negotiation may ask: those offered alone when w takes
;; them one at a time, else those offered and those its last look found
;; capable; #f, the whole lab, before it has looked.
(define (try-claim w offered)
  (cond ((and (pair? offered) (one-at-a-time? w)) offered)
        ((list? (waiter-capable w)) (append offered (waiter-capable w)))
        (else #f)))

;; Whom a negotiation of claim asks: all of it but those excluded.
(define (audience claim excluded)
  (and claim (remove (lambda (uid) (memq uid excluded)) claim)))

(define (not-offered w offered)
  (if (and (pair? offered) (list? (waiter-capable w)) (one-at-a-time? w))
      (remove (lambda (uid) (memq uid offered)) (waiter-capable w))
      '()))

;; Whether w can take robots one at a time: it holds, or needs one.
(define (one-at-a-time? w)
  (or (turn-hold? (task-turn (waiter-task w))) (= 1 (length (waiter-components w)))))

(define (look-due? w)
  (or (not (waiter-looked w)) (> (- (monotonic-seconds) (waiter-looked w)) 1)))

(define (past? deadline) (and deadline (>= (monotonic-seconds) deadline)))

(define (next-look deadline)
  (let ((look (+ (monotonic-seconds) (look-period))))
    (if deadline (min deadline look) look)))

;; A try that answers at once and neither asks the lab why it found too
;; few takers nor writes it: the waiter's look explains.
(define (quiet-try try)
  (parameterize ((pose-task-retries 0) (pose-task-explain #f)
                 (current-error-port (open-output-string)))
    (try)))

;;; The poser's look, for all its waiting tasks at once

;; Under (tasks-lock), as a task starts to wait: the first look comes at
;; once, so that the tasks posed after it know their robots (known-capable!).
(define (start-looker!)
  (when (not (looking-looker? (the-looking)))
    (looking-looker?-set! (the-looking) #t)
    (want-look!)
    (thread-start! (make-logged-thread looker 'looks))))

(define (want-look!) (mailbox-put! (looking-bell (the-looking)) #t))

;; Looks when a waiting task asks, a second after the last look at the
;; soonest, and every ten heartbeats or a third of the lease in any case,
;; until no task waits here.
(define (looker)
  (mailbox-take (looking-bell (the-looking)) (next-look #f) (lambda () #f))
  (mailbox-empty! (looking-bell (the-looking)))
  (let ((ws (with-lock (tasks-lock)
              (lambda ()
                (if (null? (waiters)) (looking-looker?-set! (the-looking) #f))
                (waiters))))
        (start (monotonic-seconds)))
    (when (pair? ws)
      (guard (e (#t (log-warn "looking at the lab: " (error-message e))))
        (look-all! ws (told-now ws)))
      (thread-sleep! (max 0 (- (+ start 1) (monotonic-seconds))))
      (looker))))

;; A look tells the best look-width tasks waiting here, and as many of
;; the rest in turn, so that it costs the same with 60 tasks waiting here
;; or 600: each of the rest is told every (n - look-width) / look-width
;; looks (docs/allocation.md).
(define look-width 32)

;; Of ws, best first, those this look tells, best first.
(define (told-now ws)
  (let ((n (length ws)))
    (if (<= n (* 2 look-width))
        ws
        (let* ((rest (list-tail ws look-width))
               (from (if (< (looking-turn (the-looking)) (- n look-width))
                         (looking-turn (the-looking))
                         0))
               (slice (take (list-tail rest from) (min look-width (- n look-width from)))))
          (looking-turn-set! (the-looking) (+ from look-width))
          (append (take ws look-width) slice)))))

;; Looks at the lab for the waiting tasks ws, and tells told, some of
;; them (told-now): one request for the takers of all their components,
;; one for the tasks that hold robots, and the lab's line
;; (line-ranks-now), whatever the number of tasks.  What each task is
;; told is made once a look for each of the layouts and numbers its
;; components have, and the holders that rank after each task are found
;; by going down both lists together (docs/allocation.md).
(define (look-all! ws told)
  (let*-values (((line) (line-ranks-now))
                ((lines fresh?) (takers-of (delete-duplicates (append-map waiter-layouts ws))
                                           (line-ranks-length line))))
    ;; Those that hold robots, no more than the robots, best first: each
    ;; task asks those of them that rank after it to give way.
    (let ((holders (list-sort (lambda (a b)
                                (rank<? (waiting-there-rank a) (waiting-there-rank b)))
                              (run-logged lab-holders "the lab's holders" '())))
          (lines-told (told-lines)))
      (if fresh?
          (remind-free! (delete-duplicates (append-map explanation-free (map cdr lines)))))
      (fold (lambda (w holders)
              (let ((after (drop-while (lambda (h)
                                         (rank<? (waiting-there-rank h) (waiter-rank w)))
                                       holders)))
                (look! w (map (lambda (l) (cdr (assoc l lines))) (waiter-layouts w))
                       after line lines-told)
                after))
            holders told))))

;; The takers of each of layouts, ((LAYOUT . EXPLANATION) ...), and
;; whether they were asked afresh; else as the last look that asked the
;; lab found them, when that was less than a heartbeat ago for every 100
;; of the n tasks waiting in the lab (docs/allocation.md).  Who is capable
;; and free, and why a task waits, may so be n/100 heartbeats old; who
;; is offered a robot is decided by the robot's round, never by this.
;; The last are kept as (WHEN (LAYOUT . EXPLANATION) ...).
(define (takers-of layouts n)
  (let ((now (monotonic-seconds))
        (last (looking-takers (the-looking))))
    (if (and last
             (< (- now (car last)) (* (setting 'heartbeat) (max 1 (/ n 100))))
             (last-explanations layouts))
        (values (cdr last) #f)
        (let ((lines (map cons layouts (explain-components layouts))))
          (looking-takers-set! (the-looking) (cons now lines))
          (values lines #t)))))

;; The last look's explanation of each of layouts; #f before a look, or
;; when it did not ask about one of them.
(define (last-explanations layouts)
  (let ((last (looking-takers (the-looking))))
    (and last
         (let ((found (map (lambda (l) (assoc l (cdr last))) layouts)))
           (and (every values found) (map cdr found))))))

;; The line a look tells of explanation e for component number i, trimmed,
;; made once a look for each.
(define (told-lines)
  (let ((made '()))
    (lambda (e i)
      (let ((key (find (lambda (m) (and (eq? (car m) e) (= (cadr m) i))) made)))
        (if key
            (car (cddr key))
            (let ((text (trimmed (explanation-line e i))))
              (set! made (cons (list e i text) made))
              text))))))

(define (waiter-layouts w)
  (map (lambda (c) (capability-layout (component-capabilities c))) (waiter-components w)))

;; What a look tells w, from lines, the explanations of its components,
;; holders, the lab's waiting tasks that hold robots and rank after it,
;; line, the ranks of all its waiting tasks in order, and told, its
;; lines' text: why it waits, and its place in line, in its components'
;; states; or why it never can be served, its waiting task told.
(define (look! w lines holders line told)
  (waiter-looked-set! w (monotonic-seconds))
  (let* ((cs (waiter-components w))
         (capable (capable-lists w lines))
         (never (cond
                 ((any null? capable)
                  (string-append "no live robot of the lab is capable of it:"
                                 (apply string-append (explanation-lines lines))))
                 ((too-few-capable? cs capable)
                  "fewer live robots of the lab are capable of it than it has components")
                 (else #f))))
    (cond
     (never
      (waiter-never-set! w never)
      (tell-waiter! w '(looked)))
     (else
      (capable-set! w capable)
      (waiter-why-set! w (map told lines (iota (length lines) 1)))
      (ask-way! w lines holders)
      (if (blocked-on-itself? w) (tell-waiter! w '(looked)))
      (move-up! w line)
      (progress (task-id (waiter-task w)) ": " (task-state (waiter-task w))
                (if (pair? (waiter-held w))
                    (apply string-append
                           (map (lambda (uid) (string-append " " (symbol->string uid)))
                                (held-uids w)))
                    "")
                ", " (waiter-position w) " in line")))))

;; The uids of each of lines, w's components' explanations, w may use.
(define (capable-lists w lines)
  (map (lambda (line)
         (let ((all (explanation-capable line)))
           (if (null? (waiter-excluded w))
               all
               (remove (lambda (uid) (memq uid (waiter-excluded w))) all))))
       lines))

;; A task that starts to wait takes its capable robots from its poser's
;; last look, when that found some for each of its layouts: its first try
;; asks them, not the whole lab, and robots that cannot serve it pass it
;; by.  Under (tasks-lock).
(define (known-capable! w)
  (let* ((lines (last-explanations (waiter-layouts w)))
         (capable (and lines (capable-lists w lines))))
    (if (and capable (every pair? capable)) (capable-set! w capable))))

;; w's capable robots, capable those of each of its components.
(define (capable-set! w capable)
  (waiter-capable-set! w (union-of capable))
  (waiter-capables-set! w (map cons (waiter-components w) capable)))

;; Whether fewer robots are capable of the exclusive components of cs,
;; capable the uids capable of each, than they are: never when each has
;; as many as they are, which a look of a lab with spare robots finds at
;; once.
(define (too-few-capable? cs capable)
  (let ((exclusive (filter-map (lambda (c caps)
                                 (and (pair? (car (capability-layout (component-capabilities c))))
                                      caps))
                               cs capable)))
    (and (any (lambda (caps) (< (length caps) (length exclusive))) exclusive)
         (< (length (union-of exclusive)) (length exclusive)))))

;; The uids in any of lists, once each.
(define (union-of lists)
  (fold (lambda (uids out)
          (append (remove (lambda (uid) (memq uid out)) uids) out))
        '() lists))

;; Robots that a look finds free may have made their offers before these
;; tasks waited, or be making them: each found free by the last look too
;; is asked to offer itself (again), best rank first, rather than taken by
;; a try out of turn.  A robot just freed is offering itself already: a
;; look that reminded every robot it found free, with hundreds of tasks
;; waiting, kept them all answering reminders.  The free robots of the
;; last look are kept.

(define (remind-free! free)
  (for-each (lambda (uid)
              (guard (e (#t (log-warn "reminding " uid ": " (error-message e))))
                (parameterize ((remote-timeout 1))
                  (remote-apply (uid->aspace uid) note-waiters! (local-aspace-uid)))))
            (filter (lambda (uid) (memq uid (looking-free-seen (the-looking)))) free))
  (looking-free-seen-set! (the-looking) free))

(define (trimmed line)
  (let loop ((s line))
    (cond ((and (> (string-length s) 0) (char-whitespace? (string-ref s 0)))
           (loop (substring s 1 (string-length s))))
          ((and (> (string-length s) 0)
                (char-whitespace? (string-ref s (- (string-length s) 1))))
           (loop (substring s 0 (- (string-length s) 1))))
          (else s))))

;; Brings w's place in the lab's line, its state and its components'
;; states up to date: holding while it holds a robot, each component it
;; holds a robot for (holding UID), the others (waiting PLACE WHY).
;; line is the lab's line (line-ranks-now), asked for when
;; not given.
(define (move-up! w . line)
  (let ((place (guard (e (#t (waiter-position w)))
                 (place-in-line w (if (pair? line) (car line) (line-ranks-now)))))
        (t (waiter-task w)))
    (with-lock (tasks-lock)
      (lambda ()
        (waiter-position-set! w place)
        (if (and (pair? (waiter-why w)) (memq (task-state t) '(negotiating waiting holding)))
            (task-state-set! t (if (pair? (waiter-held w)) 'holding 'waiting)))
        (for-each (lambda (c why)
                    (cond ((assv (component-index c) (waiter-held w))
                           => (lambda (h) (component-state-set! c (list 'holding (held-uid h)))))
                          ((and (pair? (waiter-why w))
                                (memq (car (component-state c))
                                      '(negotiating waiting holding)))
                           (component-state-set! c (list 'waiting place why)))))
                  (waiter-components w)
                  (if (pair? (waiter-why w))
                      (waiter-why w)
                      (map (lambda (c) "") (waiter-components w))))))))

;; Tells w, just posed, to try at once when no better-ranked task of the
;; lab waits; from a thread of its own, as asking the posers may take
;; seconds, and w answers its offers meanwhile.
(define (check-first! w)
  (let ((posed (monotonic-seconds)))
    (thread-start!
     (make-logged-thread (lambda () (if (not (behind-others? w posed)) (tell-waiter! w '(first))))
                         'first))))

;; Whether a better-ranked task of the lab waits, or w waits no more: w,
;; just posed, has not looked at which robots it may use.  The other
;; posers are asked after w was posed: an older answer lacks the tasks
;; posed elsewhere just before it.
(define (behind-others? w posed)
  (or (let ((ws (with-lock (tasks-lock) waiters)))
        (or (not (memq w ws)) (rank<? (waiter-rank (car ws)) (waiter-rank w))))
      (any (lambda (o) (rank<? (waiting-there-rank o) (waiter-rank w)))
           (run-logged (lambda () (waiting-at-others posed))
                       "the other posers' waiting tasks" '()))))
