;;; tools/chibi examples/box-judge.scm B14-LOG NAME LAB [TRACE POSE-OUT]:
;;; where the box of LAB ended, as the simulator says when it stops ("b14:
;;; box 0 ends at X Y HEADING after T s"), against the goal of the path its
;;; code files define (box-path.scm).  With the simulator's SVG trace and
;;; the poser's output, a run where a pusher was lost is judged too by what
;;; its spare did: the spare, the robot the lost pusher's component went to,
;;; must have been in contact with the box's rear face, or within 100 mm of
;;; it, for at least nine tenths of the last third of the distance the box
;;; moved.  The simulator's word is the judge's alone: the robots only ever
;;; see the box through their fiducial finders.  Prints the verdict and the
;;; bench lines NAME-goal-error-mm, box-move-sim-seconds and, with a spare,
;;; box-move-spare-push-mm (how far the box moved while the spare was at its
;;; rear face); exits 0 when all is well, 1 when not, 2 when the log has no
;;; such line.
(import (scheme base) (scheme write) (scheme read) (scheme file) (scheme inexact)
        (scheme process-context) (scheme eval) (srfi 1) (only (meta) mutable-environment)
        (only (chibi string) string-contains string-cursor->index string-split)
        (only (chibi io) port->string))

(define (folder-of path)
  (let loop ((i (- (string-length path) 1)))
    (cond ((< i 0) "./")
          ((char=? #\/ (string-ref path i)) (substring path 0 (+ i 1)))
          (else (loop (- i 1))))))

(define (read-all file)
  (call-with-input-file file
    (lambda (in)
      (let loop ((forms '()))
        (let ((form (read in)))
          (if (eof-object? form) (reverse forms) (loop (cons form forms))))))))

;; The lab's clauses.
(define (lab-clauses lab) (cddr (car (read-all lab))))
(define (clauses-named name clauses)
  (filter (lambda (c) (and (pair? c) (eq? (car c) name))) clauses))

;; A code file the lab names: by an absolute path, or one relative to the
;; lab's folder.
(define (code-path lab file)
  (if (and (> (string-length file) 0) (char=? (string-ref file 0) #\/))
      file
      (string-append (folder-of lab) file)))

;; The lab's code files, read into an environment of their own: the lab's
;; code is written for the lab's environment, not as a library, and only
;; the path's definitions are used here.
(define (path-env lab)
  (let ((env (mutable-environment '(scheme base) '(scheme inexact))))
    (for-each (lambda (file)
                (for-each (lambda (form) (eval form env))
                          (read-all (code-path lab file))))
              (append-map cdr (clauses-named 'code (lab-clauses lab))))
    env))

(define (string-prefix? p s)
  (and (>= (string-length s) (string-length p))
       (string=? p (substring s 0 (string-length p)))))

;; read-line stops at 8191 characters, and the trace's lines are longer.
(define (read-lines file)
  (string-split (call-with-input-file file port->string) #\newline))

(define (read-after prefix line)
  (read (open-input-string (substring line (string-length prefix) (string-length line)))))

;; (X Y HEADING SECONDS) from the simulator's line, or #f.
(define (box-end log)
  (let ((prefix "b14: box 0 ends at "))
    (fold (lambda (line found)
            (if (string-prefix? prefix line)
                (let ((in (open-input-string (substring line (string-length prefix)
                                                        (string-length line)))))
                  (let* ((x (read in)) (y (read in)) (h (read in)))
                    (read in)
                    (list x y h (read in))))
                found))
          #f (read-lines log))))

(define (say . parts)
  (for-each display parts)
  (newline))

;;; The spare, from the trace

;; The robot the poser gave a lost component of step 2, or #f: the last
;; "component K reassigned from X to Y" after "step 1 done".
(define (spare pose-out)
  (let loop ((lines (read-lines pose-out)) (step-2? #f) (found #f))
    (cond ((null? lines) found)
          ((string-contains (car lines) ": step 1 done: ") (loop (cdr lines) #t found))
          ((and step-2? (string-contains (car lines) " reassigned from "))
           (let ((in (open-input-string (car lines))))
             (loop (cdr lines) #t (let skip ((w (read in)))
                                    (if (eq? w 'to) (read in) (skip (read in)))))))
          (else (loop (cdr lines) step-2? found)))))


;; The trace's columns of samples, boxes first, then robots: each a vector
;; of (X Y HEADING).  Each body's line has its translations, then its
;; rotations.
(define (trace-columns svg)
  (filter-map (lambda (line)
                (and (string-contains line "type=\"translate\"")
                     (let* ((xy (after-values line))
                            (turn (after-values (cdr xy))))
                       (list->vector
                        (map (lambda (p h) (append p h)) (car xy) (car turn))))))
              (read-lines svg)))

;; The samples of the first values="..." in text, each a list of numbers,
;; and the text after it.
(define (after-values text)
  (let* ((rest (after text "values=\"")) (end (index-of rest "\"")))
    (cons (map (lambda (sample) (map string->number (string-split sample #\,)))
               (string-split (substring rest 0 end) #\;))
          (substring rest end (string-length rest)))))

(define (index-of s part) (string-cursor->index s (string-contains s part)))
(define (after s part)
  (substring s (+ (index-of s part) (string-length part)) (string-length s)))

(define pi (acos -1))

;; Whether a robot at r (radius mm) is within 100 mm of the rear face of a
;; box at b (side mm) moving by (dx dy), the face whose normal is nearest
;; the motion's opposite, with at least a quarter of its width behind the
;; face: two bodies are wider than a small box, so a pusher pressing the
;; face may have its centre past the face's end (docs/box-move.md).
(define (at-rear? r b side radius dx dy)
  (let* ((motion (atan dy dx))
         (h (* pi (/ (list-ref b 2) 180)))
         (axis (+ h (* (/ pi 2) (round (/ (- motion h) (/ pi 2))))))
         (rx (- (car r) (car b))) (ry (- (cadr r) (cadr b)))
         (u (+ (* rx (cos axis)) (* ry (sin axis))))
         (v (- (* ry (cos axis)) (* rx (sin axis)))))
    (and (<= (- (- u) (/ side 2) radius) 100) (< u 0)
         (<= (abs v) (+ (/ side 2) (/ radius 2))))))

;; (PUSHED LAST-THIRD-SHARE TRAVEL): mm the box moved while robot k was at
;; its rear face, the share of the last third of its travel it was, and
;; the box's whole travel.
(define (spare-push box robot side radius)
  (let* ((n (min (vector-length box) (vector-length robot)))
         (steps (map (lambda (s)
                       (let* ((a (vector-ref box s)) (b (vector-ref box (+ s 1)))
                              (dx (- (car b) (car a))) (dy (- (cadr b) (cadr a)))
                              (d (sqrt (+ (* dx dx) (* dy dy)))))
                         (cons d (and (> d 0.5)
                                      (at-rear? (vector-ref robot s) a side radius
                                                dx dy)))))
                     (iota (- n 1))))
         (travel (fold + 0 (map car steps))))
    (let loop ((steps steps) (gone 0) (pushed 0) (last 0))
      (if (null? steps)
          (list pushed (if (> travel 0) (/ last (/ travel 3)) 0) travel)
          (let* ((d (car (car steps))) (at? (cdr (car steps))))
            (loop (cdr steps) (+ gone d) (if at? (+ pushed d) pushed)
                  (if (and at? (>= gone (* 2/3 travel))) (+ last d) last)))))))

;; Whether the spare pushed, saying so and its bench line.
(define (judge-spare lab svg pose-out)
  (let ((who (spare pose-out)))
    (or (not who)
        (let* ((clauses (lab-clauses lab))
               (robots (filter-map (lambda (a) (and (assq 'robot (cddr a)) (cadr a)))
                                   (clauses-named 'aspace clauses)))
               (boxes (append-map (lambda (w) (clauses-named 'box (cdr w)))
                                  (clauses-named 'world clauses)))
               (columns (trace-columns svg))
               (k (list-index (lambda (r) (eq? r who)) robots))
               (result (spare-push (car columns) (list-ref columns (+ (length boxes) k))
                                   (list-ref (car boxes) 3) (radius svg)))
               (ok? (>= (cadr result) 0.9)))
          (say "box-move: the spare " who " was at the box's rear face while it moved "
               (exact (round (car result))) " mm of " (exact (round (car (cddr result))))
               ", " (exact (round (* 100 (min 1 (cadr result))))) "% of the last third: "
               (if ok? "it pushed" "it did not push to the end"))
          (say "bench: box-move-spare-push-mm " (exact (round (car result))) " mm")
          ok?))))

(define (radius svg)
  (let ((rest (after (find (lambda (line) (string-contains line "<circle r=\""))
                           (read-lines svg))
                     "<circle r=\"")))
    (string->number (substring rest 0 (index-of rest "\"")))))

(define (judge log name lab svg pose-out)
  (let* ((end (box-end log)) (env (path-env lab))
         (from-path (lambda (name) (eval name env)))
         (goal ((from-path 'goal))) (goal-heading ((from-path 'goal-heading))))
    (if (not end)
        (begin (say "box-move: no \"b14: box 0 ends\" line in " log) (exit 2)))
    (let* ((err ((from-path 'distance) end goal))
           (turn (abs ((from-path 'square-wrap) (- (car (cddr end)) goal-heading))))
           (arrived? (and (<= err 300) (<= turn 20))))
      (say "box-move: the box ended at (" (exact (round (car end))) ", "
           (exact (round (cadr end))) ") heading " (car (cddr end)) " after "
           (cadr (cddr end)) " s; the goal is (" (car goal) ", " (cadr goal) ") heading "
           (exact (round goal-heading)) ": " (exact (round err)) " mm and "
           (exact (round turn)) " degrees off, "
           (if arrived? "within" "outside") " 300 mm and 20 degrees")
      (say "bench: " name "-goal-error-mm " (exact (round err)) " mm")
      (say "bench: box-move-sim-seconds " (cadr (cddr end)) " s")
      (let ((pushed? (or (not svg) (judge-spare lab svg pose-out))))
        (exit (if (and arrived? pushed?) 0 1))))))

(let ((args (cdr (command-line))))
  (if (not (memv (length args) '(3 5)))
      (begin (say "usage: box-judge.scm B14-LOG NAME LAB [TRACE POSE-OUT]") (exit 2)))
  (apply judge (append args (if (= (length args) 3) '(#f #f) '()))))
