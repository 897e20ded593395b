;;;; The room, checked before anything starts: a robot inside a wall, on
;;;; another robot or a box, or outside a rectangular room's walls, which
;;;; the simulator would fix or allow without a word.  Of two robots on
;;;; each other, the later in the file is named.

(define default-robot-radius 180)       ; sim/lab.c's B14
(define default-wall-thickness 50)

(define (check-room path clauses)
  (let* ((walls (world-items clauses 'wall))
         (boxes (world-items clauses 'box))
         (radius (robot-radius clauses))
         (robots (filter-map robot-place clauses)))
    (let loop ((robots robots) (before '()))
      (when (pair? robots)
        (let* ((r (car robots)) (at (place-point r)))
          (if (outside? at walls)
              (room-error path r "outside the walls of the room" ""))
          (for-each (lambda (w)
                      (if (< (wall-distance at w) (+ radius (/ (wall-thickness w) 2)))
                          (room-error path r "inside or against " w)))
                    walls)
          (for-each (lambda (b)
                      (if (< (box-distance at b) radius)
                          (room-error path r "on " b)))
                    boxes)
          (for-each (lambda (other)
                      (if (< (distance at (place-point other)) (* 2 radius))
                          (room-error path r "on the robot "
                                      (string-append
                                       (symbol->string (place-uid other))
                                       (line-words (place-aspace other))))))
                    before)
          (loop (cdr robots) (cons r before)))))))

;; Whether point is outside the bounding box of walls enclosing it on four sides.
(define (outside? point walls)
  (and (pair? walls)
       (let* ((ends (append (map wall-from walls) (map wall-to walls)))
              (xs (map car ends)) (ys (map cadr ends))
              (x0 (apply min xs)) (x1 (apply max xs))
              (y0 (apply min ys)) (y1 (apply max ys)))
         ;; A wall whose two ends have coordinate at, x (car) or y (cadr).
         (define (side? at coordinate)
           (any (lambda (w) (= at (coordinate (wall-from w)) (coordinate (wall-to w))))
                walls))
         (and (side? x0 car) (side? x1 car) (side? y0 cadr) (side? y1 cadr)
              (not (and (<= x0 (car point) x1) (<= y0 (cadr point) y1)))))))

(define (room-error path r where thing)
  (let ((aspace (place-aspace r)))
    (lab-file-error path aspace
                    (string-append "the robot " (symbol->string (place-uid r))
                                   " stands " where
                                   (if (string? thing)
                                       thing
                                       (clause-text thing))))))

;; The world's walls or boxes (kind) in clauses, with the numbers read below.
(define (world-items clauses kind)
  (let ((world (or (clause 'world clauses) '(world)))
        (n (if (eq? kind 'wall) 4 5)))
    (filter (lambda (i) (and (pair? i) (eq? (car i) kind) (list? i)
                             (>= (length (cdr i)) n)
                             (every real? (cdr i))))
            (cdr world))))

;;> The walls and the boxes of \var{lab}'s world, as clauses (wall X1 Y1 X2
;;> Y2 [THICK]) and (box X Y W D HEADING [MASS]), read by the fields below.
(define (lab-walls lab) (world-items (lab-clauses lab) 'wall))
(define (lab-boxes lab) (world-items (lab-clauses lab) 'box))

(define (robot-radius clauses)
  (let ((b14 (clause 'b14 clauses)))
    (cond ((and b14 (find (lambda (c) (and (pair? c) (eq? (car c) 'radius)
                                           (pair? (cdr c)) (real? (cadr c))))
                          (cdr b14)))
           => cadr)
          (else default-robot-radius))))

;; Where the robot of an address space clause stands.
(define-record-type place
  (make-place aspace point)
  place?
  (aspace place-aspace)
  (point place-point))

(define (place-uid p) (cadr (place-aspace p)))

(define (robot-place c)
  (and (pair? c) (eq? (car c) 'aspace) (list? c) (pair? (cdr c))
       (let* ((robot (clause 'robot (cddr c)))
              (pose (and robot (list? robot)
                         (find (lambda (x) (and (pair? x) (eq? (car x) 'pose)))
                               (cdr robot)))))
         (and pose (list? pose) (>= (length pose) 3)
              (real? (cadr pose)) (real? (car (cddr pose)))
              (make-place c (list (cadr pose) (car (cddr pose))))))))

;;> The fields of the world's clauses, by name.
(define (wall-from w) (list (list-ref w 1) (list-ref w 2)))
(define (wall-to w) (list (list-ref w 3) (list-ref w 4)))
(define (wall-thickness w)
  (if (> (length w) 5) (list-ref w 5) default-wall-thickness))
(define (box-centre b) (list (list-ref b 1) (list-ref b 2)))
(define (box-width b) (list-ref b 3))
(define (box-depth b) (list-ref b 4))
(define (box-heading b) (list-ref b 5))

(define (distance p q)
  (sqrt (+ (square (- (car p) (car q))) (square (- (cadr p) (cadr q))))))

;; From point to the wall's centre line.
(define (wall-distance point w)
  (let* ((from (wall-from w)) (to (wall-to w))
         (dx (- (car to) (car from))) (dy (- (cadr to) (cadr from)))
         (len2 (+ (square dx) (square dy)))
         (t (if (zero? len2)
                0
                (max 0 (min 1 (/ (+ (* (- (car point) (car from)) dx)
                                    (* (- (cadr point) (cadr from)) dy))
                                 len2))))))
    (distance point (list (+ (car from) (* t dx)) (+ (cadr from) (* t dy))))))

;; From point to the nearest point of the box: 0 inside it.
(define (box-distance point b)
  (let* ((x (- (car point) (car (box-centre b))))
         (y (- (cadr point) (cadr (box-centre b))))
         (hw (/ (box-width b) 2)) (hd (/ (box-depth b) 2))
         (a (* (box-heading b) (/ (acos -1) 180)))
         (u (+ (* x (cos a)) (* y (sin a))))
         (v (- (* y (cos a)) (* x (sin a)))))
    (distance (list u v) (list (max (- hw) (min hw u)) (max (- hd) (min hd v))))))
