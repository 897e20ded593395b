;;;; The live view, (murdoch view): its snapshots.
;;
;; A guest of the lab asks every address space twice a second how it is
;; (aspace-report, a robot's sonar and fiducials) and makes a snapshot: a
;; JSON object appended to the run's trace after a line for the room.  The
;; page (web/view.js) reads /trace, then /events; a replay serves a trace.

(define poll-seconds 0.5)

;; Snapshots kept for pages following along; one further behind reads the trace.
(define kept-snapshots 200)

;;; JSON

;;> \var{x} written as JSON, to a string ((chibi json): alists and vectors).
(define (json-text x)
  (let ((out (open-output-string)))
    (json-write x out)
    (get-output-string out)))

;; A number as JSON takes it: exact integers as they are, else to a tenth.
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

;;> The first line of a trace, as JSON: the lab's name, robot radius,
;;> walls, boxes, and address spaces.
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

;;> Where box \var{id} is, (x y heading), seen from a robot at \var{pose}.
(define (box-seen pose range bearing orientation)
  (let ((a (degrees->radians (+ (list-ref pose 2) bearing))))
    (list (+ (car pose) (* range (cos a)))
          (+ (cadr pose) (* range (sin a)))
          (+ (list-ref pose 2) orientation))))

;;; Snapshots

;; What each address space is asked: its report, a robot's sonar and
;; fiducials, and the tasks it posed lately, over or not.
(define report-source
  '(lambda ()
     (list (aspace-report)
           (guard (e (#t #f)) (sonar-read))
           (guard (e (#t #f)) (fiducials))
           (let ((posed (filter listed-posed? (tasks))))
             (if (> (length posed) 12) (take posed 12) posed)))))

(define (look-report look) (car look))
(define (look-sonar look) (cadr look))
(define (look-seen look) (car (cddr look)))
;; A peer older than POSED answers none.
(define (look-posed look) (and (> (length look) 3) (list-ref look 3)))

(define-record-type ring
  (make-ring uid ranges pose)
  ring?
  (uid ring-uid)
  (ranges ring-ranges)
  (pose ring-pose))

;; What the view remembers between polls: the boxes, the task table, and
;; each robot's last sonar ring with the pose it was read at.
(define-record-type view-state
  (make-view-state boxes table sonars)
  view-state?
  (boxes view-state-boxes)
  (table view-state-table)
  (sonars view-state-sonars view-state-sonars-set!))  ; rings

;;> The view's memory at the start, for the room \var{header}.
(define (new-view-state header)
  (make-view-state (list->vector (vector->list (cdr (assq 'boxes header))))
                   (make-task-table) '()))

;;> The snapshot at \var{t} seconds of the lab, from \var{answers} and
;;> \var{state}, brought up to date; \var{line} the lab's waiting tasks.
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
            (sonar . ,(if ring (numbers (ring-ranges ring)) 'null))
            (sonar-at . ,(if ring (numbers (ring-pose ring)) 'null))
            ;; Where the robot's goto-xy is going.
            (goal . ,(let ((goal (report-goal report)))
                       (if (and (list? goal) (>= (length goal) 2)
                                (every real? (take goal 2)))
                           (numbers (take goal 2))
                           'null))))))))

;;; The feed: snapshots for the trace file and the pages that follow

;; The trace is written a line at a time, so a lab stopped any way leaves one.
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

;; The feed's snapshots from next on, once there is one, or none after seconds.
(define (feed-after feed next seconds)
  (let ((deadline (+ (monotonic-seconds) seconds)))
    (let loop ()
      (lock! (feed-lock feed))
      (let ((new (filter (lambda (r) (>= (car r) next)) (feed-recent feed)))
            (left (seconds-until deadline)))
        (cond ((or (pair? new) (= left 0.))   ; inexact: see seconds-until
               (unlock! (feed-lock feed))
               (reverse new))
              (else
               (unlock-waiting! (feed-lock feed) (feed-changed feed) left)
               (loop)))))))
