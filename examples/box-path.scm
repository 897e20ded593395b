;;; The box's path (box-lab.scm): the waypoints its centre goes through,
;;; in the room's millimetres, from where it starts to the goal.  The box
;;; has arrived when its centre is within 300 mm of the goal and its heading
;;; within 20 degrees of the last leg's, a square box's heading being the
;;; same every quarter turn.  box-move.scm moves it; `make demo-box` and
;;; tests/box-move-test.scm judge where it ended (box-judge.scm).

(define box-path '((-1500 0) (300 0) (1800 900)))

;; The box's side, mm: the fiducial finder tells where the box is, not how
;; big it is.
(define box-side 600)

(define degrees (/ (acos -1) 180))

(define (goal) (list-ref box-path (- (length box-path) 1)))

;; The heading the box should end with: its last leg's.
(define (goal-heading)
  (heading-to (list-ref box-path (- (length box-path) 2)) (goal)))

(define (distance p q)
  (sqrt (+ (square (- (car p) (car q))) (square (- (cadr p) (cadr q))))))

;; The heading from p to q, degrees.
(define (heading-to p q) (/ (atan (- (cadr q) (cadr p)) (- (car q) (car p))) degrees))

;; An angle in (-180, 180]; a square box's heading in (-45, 45].
(define (wrap a) (- a (* 360 (round (/ a 360)))))
(define (square-wrap a) (- a (* 90 (round (/ a 90)))))
