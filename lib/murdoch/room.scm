;;;; The room, checked before anything starts: a robot placed inside a
;;;; wall, or on another robot or a box, is a mistake that the simulator
;;;; would undo without a word, by pushing the bodies apart; one outside
;;;; the walls of a rectangular room would drive about outside it.  Of
;;;; two robots on each other, the later in the file is named, as the
;;;; one placed where the other stood.

(define default-robot-radius 180)       ; sim/lab.c's B14
(define default-wall-thickness 50)

(define (check-room path clauses)
  (let* ((world (or (clause 'world clauses) '(world)))
         (walls (items 'wall 4 (cdr world)))
         (boxes (items 'box 5 (cdr world)))
         (radius (robot-radius clauses))
         (robots (filter-map robot-place clauses)))
    (let loop ((robots robots) (before '()))
      (when (pair? robots)
        (let ((r (car robots)))
          (if (outside? (cdr r) walls)
              (room-error path r "outside the walls of the room" ""))
          (for-each (lambda (w)
                      (if (< (wall-distance (cadr r) (car (cddr r)) w)
                             (+ radius (/ (wall-thickness w) 2)))
                          (room-error path r "inside or against " w)))
                    walls)
          (for-each (lambda (b)
                      (if (< (box-distance (cadr r) (car (cddr r)) b) radius)
                          (room-error path r "on " b)))
                    boxes)
          (for-each (lambda (other)
                      (if (< (distance (cdr r) (cdr other)) (* 2 radius))
                          (room-error path r "on the robot "
                                      (string-append (symbol->string (cadr (car other)))
                                                     (line-words (car other))))))
                    before)
          (loop (cdr robots) (cons r before)))))))

;; Whether (x y) is outside the bounding box of walls that enclose it: a
;; wall along each of its four sides.
(define (outside? p walls)
  (and (pair? walls)
       (let* ((xs (append-map (lambda (w) (list (list-ref w 1) (list-ref w 3))) walls))
              (ys (append-map (lambda (w) (list (list-ref w 2) (list-ref w 4))) walls))
              (x0 (apply min xs)) (x1 (apply max xs))
              (y0 (apply min ys)) (y1 (apply max ys)))
         (define (side? at x-or-y)
           (any (lambda (w) (and (= (list-ref w x-or-y) at)
                                 (= (list-ref w (+ x-or-y 2)) at)))
                walls))
         (and (side? x0 1) (side? x1 1) (side? y0 2) (side? y1 2)
              (not (and (<= x0 (car p) x1) (<= y0 (cadr p) y1)))))))

(define (room-error path r where thing)
  (let ((aspace (car r)))
    (lab-file-error path aspace
                    (string-append "the robot " (symbol->string (cadr aspace))
                                   " stands " where
                                   (if (string? thing)
                                       thing
                                       (clause-text thing))))))

;; The world's items of kind with at least n numbers.
(define (items kind n ls)
  (filter (lambda (i) (and (pair? i) (eq? (car i) kind) (list? i)
                           (>= (length (cdr i)) n)
                           (every real? (cdr i))))
          ls))

(define (robot-radius clauses)
  (let ((b14 (clause 'b14 clauses)))
    (cond ((and b14 (find (lambda (c) (and (pair? c) (eq? (car c) 'radius)
                                           (pair? (cdr c)) (real? (cadr c))))
                          (cdr b14)))
           => cadr)
          (else default-robot-radius))))

;; (ASPACE-CLAUSE X Y) of an address space with a robot at a pose, or #f.
(define (robot-place c)
  (and (pair? c) (eq? (car c) 'aspace) (list? c) (pair? (cdr c))
       (let* ((robot (clause 'robot (cddr c)))
              (pose (and robot (list? robot)
                         (find (lambda (x) (and (pair? x) (eq? (car x) 'pose)))
                               (cdr robot)))))
         (and pose (list? pose) (>= (length pose) 3)
              (real? (cadr pose)) (real? (car (cddr pose)))
              (list c (cadr pose) (car (cddr pose)))))))

(define (wall-thickness w)
  (if (> (length w) 5) (list-ref w 5) default-wall-thickness))

(define (distance p q)
  (sqrt (+ (square (- (car p) (car q))) (square (- (cadr p) (cadr q))))))

;; From (x y) to the wall's centre line.
(define (wall-distance x y w)
  (let* ((x1 (list-ref w 1)) (y1 (list-ref w 2)) (x2 (list-ref w 3)) (y2 (list-ref w 4))
         (dx (- x2 x1)) (dy (- y2 y1))
         (len2 (+ (square dx) (square dy)))
         (t (if (zero? len2) 0
                (max 0 (min 1 (/ (+ (* (- x x1) dx) (* (- y y1) dy)) len2))))))
    (distance (list x y) (list (+ x1 (* t dx)) (+ y1 (* t dy))))))

;; From (x y) to the nearest point of the box: 0 inside it.
(define (box-distance x y b)
  (let* ((cx (list-ref b 1)) (cy (list-ref b 2))
         (hw (/ (list-ref b 3) 2)) (hd (list-ref b 4))
         (a (* (list-ref b 5) (/ (acos -1) 180)))
         ;; (x y) in the box's frame
         (u (+ (* (- x cx) (cos a)) (* (- y cy) (sin a))))
         (v (- (* (- y cy) (cos a)) (* (- x cx) (sin a)))))
    (distance (list u v) (list (max (- hw) (min hw u))
                               (max (- (/ hd 2)) (min (/ hd 2) v))))))
