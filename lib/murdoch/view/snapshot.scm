;;;; The live view, (murdoch view): its snapshots.
;;
;; One process, a guest of the lab, asks every address space at once,
;; twice a second, how it is -- task/status.scm's aspace-report and, on a
;; robot, its latest sonar ring and the boxes its fiducial finder sees --
;; and makes of the answers a snapshot: one JSON object with the time,
;; every address space, where the boxes are, and the tasks.  Snapshots
;; are appended to the run's trace, one line each, after a line that
;; describes the room.  The page (web/view.html, web/view.js) reads the
;; trace so far from /trace and then each new snapshot from /events, as
;; server-sent events; a replay serves a finished trace and no events, and
;; the same page plays it.  The server is (chibi net http-server), on
;; 127.0.0.1 only.
;;
;; The room is the lab file's world; a box is drawn where the lab file
;; puts it until a robot's fiducial finder sees it, then where that robot
;; saw it last.  A robot's pose is its odometry (safe-reckon), which the
;; simulator starts at the lab file's pose.

(define poll-seconds 0.5)

;; Snapshots kept in memory for the pages that are following along; one
;; that falls further behind reads the trace again.
(define kept-snapshots 200)

;;; JSON

;;> \var{x} written as JSON, to a string: objects are alists of symbols,
;;> arrays vectors (chibi json).
(define (json-text x)
  (let ((out (open-output-string)))
    (json-write x out)
    (get-output-string out)))

;; A number as JSON takes it: exact integers as they are, anything else
;; to a tenth.
(define (num x)
  (cond ((exact-integer? x) x)
        ((and (real? x) (finite? x)) (/ (round (* 10. x)) 10.))
        (else 'null)))

(define (text x)
  (cond ((string? x) x)
        ((symbol? x) (symbol->string x))
        ((error-object? x) (error-message x))
        (else (let ((out (open-output-string)))
                (display x out)
                (get-output-string out)))))

(define (numbers ls) (list->vector (map num ls)))

;;; The room: the first line of a trace

;;> The first line of a trace, as JSON: the lab's name, the robots'
;;> radius, its walls as (x1 y1 x2 y2 thickness), its boxes as (x y
;;> width depth heading), and its address spaces, robots or not.
(define (lab-header lab)
  `((kind . "lab")
    (lab . ,(symbol->string (lab-name lab)))
    (radius . ,(num (lab-robot-radius lab)))
    (walls . ,(list->vector
               (map (lambda (w)
                      (numbers (append (wall-from w) (wall-to w)
                                       (list (wall-thickness w)))))
                    (lab-walls lab))))
    (boxes . ,(list->vector
               (map (lambda (b)
                      (numbers (append (box-centre b)
                                       (list (box-width b) (box-depth b)
                                             (box-heading b)))))
                    (lab-boxes lab))))
    (aspaces . ,(list->vector
                 (map (lambda (a)
                        `((name . ,(symbol->string (lab-aspace-uid a)))
                          (robot . ,(if (lab-aspace-clause a 'robot) #t #f))))
                      (lab-aspaces lab))))
    (started . ,(num (utc-seconds)))))

(define (degrees->radians d) (* d (/ (acos -1) 180)))

;;> Where box \var{id} is, as (x y heading), from a robot at \var{pose}
;;> (x y heading ...) that sees it at \var{range} mm and \var{bearing}
;;> degrees, the box's heading being \var{orientation} degrees from the
;;> robot's.
(define (box-seen pose range bearing orientation)
  (let ((a (degrees->radians (+ (list-ref pose 2) bearing))))
    (list (+ (car pose) (* range (cos a)))
          (+ (cadr pose) (* range (sin a)))
          (+ (list-ref pose 2) orientation))))

;;; Snapshots

;; What each address space is asked: its report, on a robot its sonar
;; ring and fiducials (#f on a workstation, where they raise), and the
;; tasks it posed lately, over or not: the report leaves out those over,
;; and a task ends in the state its poser gives it.
(define report-source
  '(lambda ()
     (list (aspace-report)
           (guard (e (#t #f)) (sonar-read))
           (guard (e (#t #f)) (fiducials))
           (let ((posed (filter listed-posed? (tasks))))
             (if (> (length posed) 12) (take posed 12) posed)))))

;; The parts of what report-source answers, a look at one address space.
(define (look-report look) (car look))
(define (look-sonar look) (cadr look))
(define (look-seen look) (car (cddr look)))
;; A peer older than POSED answers none.
(define (look-posed look) (and (> (length look) 3) (list-ref look 3)))

;; A robot's last sonar ring, and the pose it was first read at.
(define-record-type ring
  (make-ring uid ranges pose)
  ring?
  (uid ring-uid)
  (ranges ring-ranges)
  (pose ring-pose))

;; What the view remembers from one poll to the next: where the boxes
;; are, the task table, and for each robot its last sonar ring with the
;; pose it was first seen at.  A ring stays readable after sonar-stop, so
;; a robot that stopped its sonar and drove on still answers the ring it
;; read back there, which is drawn from there.
(define-record-type view-state
  (make-view-state boxes table sonars)
  view-state?
  (boxes view-state-boxes)
  (table view-state-table)
  (sonars view-state-sonars view-state-sonars-set!))  ; rings

;;> The view's memory, at the start, for the room \var{header} (see
;;> lab-header).
(define (new-view-state header)
  (make-view-state (list->vector (vector->list (cdr (assq 'boxes header))))
                   (make-task-table) '()))

;;> The snapshot at \var{t} seconds of the lab: \var{answers} are
;;> remote-apply-all's, for the lab's address spaces, of report-source;
;;> \var{state} what the view remembers (new-view-state), brought up to
;;> date; \var{line}, when given, the lab's waiting tasks as lab-line has
;;> them, a guest's too.
(define (view-snapshot lab t answers state . line)
  (let* ((answered (filter outcome-ok? answers))
         (boxes (view-state-boxes state)))
    (task-table-update! (view-state-table state) t
                        (map (lambda (o)
                               (let ((look (outcome-value o)))
                                 (cons* (outcome-uid o) (look-report look)
                                        (if (look-posed look)
                                            (list (look-posed look))
                                            '()))))
                             answered))
    (if (pair? line) (task-table-note-line! (view-state-table state) (car line)))
    (for-each (lambda (o) (move-boxes! boxes (outcome-value o))) answered)
    (for-each (lambda (o) (note-sonar! state (outcome-uid o) (outcome-value o)))
              answered)
    `((kind . "state")
      (t . ,(num t))
      (clock . ,(num (utc-seconds)))
      (aspaces . ,(list->vector (map (lambda (a) (aspace-json a state)) answers)))
      (boxes . ,(vector-map (lambda (b) b) boxes))
      (tasks . ,(task-table->json (view-state-table state) 12)))))

;; The ring the view remembers of uid, or #f.
(define (ring-of state uid)
  (find (lambda (r) (eq? (ring-uid r) uid)) (view-state-sonars state)))

;; Remembers uid's sonar ring, with its pose now when the ring is new.
(define (note-sonar! state uid look)
  (let ((ranges (look-sonar look))
        (pose (report-pose (look-report look)))
        (old (ring-of state uid)))
    (if (and (list? ranges) (pair? ranges) (every real? ranges) (list? pose)
             (>= (length pose) 3)
             (not (and old (equal? (ring-ranges old) ranges))))
        (view-state-sonars-set!
         state (cons (make-ring uid ranges (take pose 3))
                     (remove (lambda (r) (eq? (ring-uid r) uid))
                             (view-state-sonars state)))))))

(define (move-boxes! boxes look)
  (let ((pose (report-pose (look-report look)))
        (seen (look-seen look)))
    (if (and pose (list? seen))
        (for-each
         (lambda (f)
           (let ((id (fiducial-id f)))
             (if (and (exact-integer? id) (< -1 id (vector-length boxes)))
                 (let ((b (vector-ref boxes id))
                       (at (box-seen pose (fiducial-range f) (fiducial-bearing f)
                                     (fiducial-orientation f))))
                   (vector-set! boxes id
                                (vector (num (car at)) (num (cadr at))
                                        (vector-ref b 2) (vector-ref b 3)
                                        (num (car (cddr at)))))))))
         seen))))

(define (aspace-json o state)
  (let ((name (text (outcome-uid o))))
    (if (not (outcome-ok? o))
        `((name . ,name) (away . #t) (why . ,(text (outcome-value o))))
        (let* ((report (look-report (outcome-value o)))
               (ring (ring-of state (outcome-uid o)))
               (pose (report-pose report))
               (battery (report-battery report)))
          `((name . ,name)
            (away . #f)
            (since . ,(num (report-since report)))
            (pose . ,(if (and (list? pose) (>= (length pose) 3))
                         (numbers (take pose 3))
                         'null))
            (battery . ,(if (real? battery) (num (/ battery 10)) 'null))
            (held . ,(list->vector (map (lambda (h) (vector (car h) (cdr h)))
                                        (held-texts report))))
            ;; The last sonar ring, and the pose it was read at.
            (sonar . ,(if ring (numbers (ring-ranges ring)) 'null))
            (sonar-at . ,(if ring (numbers (ring-pose ring)) 'null))
            ;; Where the robot's goto-xy is going (aspace-report's GOAL).
            (goal . ,(let ((goal (report-goal report)))
                       (if (and (list? goal) (>= (length goal) 2)
                                (every real? (take goal 2)))
                           (numbers (take goal 2))
                           'null))))))))

;;; The feed: snapshots for the trace file and the pages that follow

;; The trace is written as the run goes, a line at a time, so that a
;; lab stopped any way leaves a trace to replay.  The pages that follow
;; it wait on changed for the next snapshot.
(define-record-type feed
  (%make-feed trace out count recent lock changed)
  feed?
  (trace feed-trace)                    ; the trace file's path
  (out feed-out)                        ; and its port
  (count feed-count feed-count-set!)    ; snapshots so far
  (recent feed-recent feed-recent-set!) ; ((INDEX . JSON) ...), newest first
  (lock feed-lock)
  (changed feed-changed))

(define (make-feed trace out count)
  (%make-feed trace out count '() (make-mutex 'feed) (make-condition-variable 'feed)))

(define (feed-add! feed line)
  (write-string line (feed-out feed))
  (newline (feed-out feed))
  (flush-output-port (feed-out feed))
  (with-lock (feed-lock feed)
    (lambda ()
      (let ((k (feed-count feed)))
        (feed-recent-set! feed (let ((r (cons (cons k line) (feed-recent feed))))
                                 (if (> (length r) kept-snapshots)
                                     (take r kept-snapshots)
                                     r)))
        (feed-count-set! feed (+ k 1))
        (condition-variable-broadcast! (feed-changed feed))))))

;; The snapshots numbered next or later that the feed still keeps, oldest
;; first, as soon as there is one, or none once seconds have passed.
(define (feed-after feed next seconds)
  (let ((deadline (+ (monotonic-seconds) seconds)))
    (let loop ()
      (mutex-lock! (feed-lock feed))
      (let ((new (filter (lambda (r) (>= (car r) next)) (feed-recent feed)))
            (left (seconds-until deadline)))
        (cond ((or (pair? new) (= left 0.))   ; inexact: see seconds-until
               (mutex-unlock! (feed-lock feed))
               (reverse new))
              (else
               (mutex-unlock! (feed-lock feed) (feed-changed feed) left)
               (loop)))))))
