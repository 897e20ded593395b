;;; A team moves a box along a path (thesis §1.2; MURDOCH 2002): two
;;; pushers push it from behind, and a watcher watches it with its
;;; fiducial finder and tells the pushers where it is.  No one reads where
;;; the box is in the simulator: the watcher sees it as a sensor would.
;;;
;;; (box-move-task) is the task: two steps, run by start-steps.
;;;   1. Take places: each pusher drives to its side behind the box, the
;;;      watcher turns to face the path.
;;;   2. Move the box: at the barrier push, the pushers start; the watcher
;;;      sends each its sighting of the box every 0.2 s; each pusher keeps
;;;      the box's heading on the path by pushing harder or softer on its
;;;      side; they stop when the box reaches the goal.
;;; The pushers' components may restart: a pusher that fails is replaced by
;;; a spare robot, which takes its side behind the box wherever the box is.

(define box-half 300)                   ; half the box's side, mm
(define body-radius 180)                ; a B14's
(define pusher-offset 170)              ; each pusher's offset from the centre line
(define push-speed 220)                 ; mm/s

;; The box as this robot sees it, (X Y HEADING) in the room, or #f.
(define (see-box)
  (let ((seen (fiducials)))
    (and (pair? seen)
         (let* ((f (car seen)) (me (reckon))
                (a (* degrees (+ (list-ref me 2) (list-ref f 2)))))
           (list (+ (car me) (* (list-ref f 1) (cos a)))
                 (+ (cadr me) (* (list-ref f 1) (sin a)))
                 (+ (list-ref me 2) (list-ref f 3)))))))


;; The distance from point p to the leg from a to b.
(define (leg-distance p a b)
  (let* ((dx (- (car b) (car a))) (dy (- (cadr b) (cadr a)))
         (t (/ (+ (* (- (car p) (car a)) dx) (* (- (cadr p) (cadr a)) dy))
               (+ (* dx dx) (* dy dy))))
         (t (max 0 (min 1 t))))
    (distance p (list (+ (car a) (* t dx)) (+ (cadr a) (* t dy))))))


;; Whether the box has reached the goal: near it, or past it along the
;; path's last leg.
(define (arrived? box)
  (let* ((g (goal)) (from (list-ref box-path (max 0 (- (length box-path) 2))))
         (d (* degrees (heading-to from g))))
    (or (< (distance box g) 120)
        (>= (+ (* (- (car box) (car g)) (cos d)) (* (- (cadr box) (cadr g)) (sin d)))
            -60))))

;; Where a pusher stands behind the box on its side (+1 left, -1 right),
;; pushing toward d degrees.
(define (behind box d side) (behind-at box d (* side pusher-offset)))

;; The place behind the box, pushing toward d degrees, offset mm to the
;; left of its centre line.
(define (behind-at box d offset)
  (let ((back (+ box-half body-radius 40)) (a (* d degrees)))
    (list (- (+ (car box) (* offset (- (sin a)))) (* back (cos a)))
          (- (+ (cadr box) (* offset (cos a))) (* back (sin a))))))

;;; The watcher

(define (watch-place previous) (rotate 'to -90) (local-aspace-uid))

;; Tells the pushers where the box is until both say they are done.
(define (watch previous)
  (team-barrier 'push 120)
  (let loop ((done 0) (n 0))
    (let ((box (see-box)))
      (if box
          (for-each (lambda (uid) (if (not (eq? uid (local-aspace-uid)))
                                      (team-send! uid box)))
                    (step-team)))
      (let ((heard (guard (e (#t #f)) (team-receive 0.2))))
        (cond ((and heard (eq? (cdr heard) 'done) (= done 1)) (or box 'lost-sight))
              ((> n 900) 'gave-up)
              (else (loop (+ done (if (and heard (eq? (cdr heard) 'done)) 1 0))
                          (+ n 1))))))))

;;; The pushers

;; The team as it is now: a spare may have replaced a pusher.
(define (my-side) (if (eq? (local-aspace-uid) (car (step-team))) 1 -1))

(define (take-place previous)
  (let ((box (or (see-box) '(-1500 0 0))))
    (go-to-place box)
    (local-aspace-uid)))

;; Drives to this pusher's place behind the box, facing along it.
(define (go-to-place box)
  (let ((axis (place-axis box)))
    (goto-xy (behind box axis (my-side)))
    (rotate 'to axis)))

(define (place-axis box) (box-axis box (heading-to box (aim-point box))))

;; A spare comes up to its place from well behind it and out to its side,
;; so as not to cross the other pusher's way.
(define (come-up-to-place box)
  (let* ((axis (place-axis box)) (a (* axis degrees)) (side (my-side))
         (place (behind box axis side)))
    (goto-xy (list (- (car place) (* 700 (cos a)) (* side 300 (sin a)))
                   (+ (- (cadr place) (* 700 (sin a))) (* side 300 (cos a)))))
    (go-to-place box)))

;; The other pusher, and the rounds since it last said it was there.
(define (partner) (list-ref (step-team) (if (= (my-side) 1) 1 0)))
(define partner-silent 0)

;; The newest sighting the watcher sent, or last when none came; the
;; partner's word that it is there is counted.
(define (latest last)
  (let ((heard (guard (e (#t #f)) (team-receive 0.05))))
    (cond ((not heard) last)
          ((eq? (cdr heard) 'here) (set! partner-silent 0) (latest last))
          ((pair? (cdr heard)) (latest (cdr heard)))
          (else (latest last)))))

;; Each round a pusher tells its partner it is there.  A pusher lost is
;; replaced by a spare, which comes up to its place wherever the box is;
;; meanwhile the other pushes alone (steer!).
(define (push previous)
  (team-barrier 'push 120)
  ;; A spare that took over midway is not yet behind the box.
  (let ((box (latest (see-box))))
    (if (and box (> (distance (reckon) (behind box (place-axis box) (my-side))) 300))
        (come-up-to-place box)))
  (set! partner-silent 0)
  (let ((watcher (list-ref (step-team) 2)))
    (let loop ((box (latest (see-box))) (n 0))
      (team-send! (partner) 'here)
      (set! partner-silent (+ partner-silent 1))
      (cond
       ((and box (arrived? box))
        (set-velocity 0 0)
        (team-send! watcher 'done)
        (local-aspace-uid))
       ((> n 1500) (set-velocity 0 0) (team-send! watcher 'done) 'gave-up)
       (else
        (if box (steer! box (<= partner-silent 3)))
        (thread-sleep! 0.1)
        (loop (latest box) (+ n 1)))))))

;; Each pusher keeps to its place at the box's rear face and drives along
;; the box's axis, hurrying when it has fallen behind its place.  Two
;; pushers stand pusher-offset to either side of the middle, and the box
;; turns toward the path when the one on the far side of the turn pushes
;; harder.  A pusher alone (its partner silent for three rounds) turns the
;; box by where it pushes: at the middle of the face to go straight, to
;; the right of it to turn left; at one corner, at full speed, it would
;; drag the box off its path.
(define (steer! box paired?)
  (let* ((side (my-side))
         (d (heading-to box (aim-point box)))
         (axis (box-axis box d))
         (err (wrap (- d axis)))                ; > 0: the box must turn left
         (a (* axis degrees))
         (slot (behind-at box axis (if paired?
                                       (* side pusher-offset)
                                       (clip (* -8 err) pusher-offset))))
         (me (reckon))
         (dx (- (car me) (car slot))) (dy (- (cadr me) (cadr slot)))
         (lag (- (+ (* dx (cos a)) (* dy (sin a)))))      ; behind the place
         (across (- (* dy (cos a)) (* dx (sin a))))       ; left of it
         (turn (wrap (- (- axis (clip (* 0.15 across) 25)) (list-ref me 2))))
         (speed (* push-speed (slowing box)
                   (+ (if paired? (clip (- 1 (* 0.05 side err)) 0.3 1.7) 0.5)
                      (clip (/ lag 100) 0 1)))))
    (set-velocity speed (clip (* 2 turn) 40))))

(define (clip x lo . hi)
  (if (pair? hi) (max lo (min (car hi) x)) (max (- lo) (min lo x))))

;; Full speed, down to a third within the last 600 mm, so that the box
;; does not slide past the goal.
(define (slowing box) (clip (/ (distance box (goal)) 600) 0.33 1))

;; The box's axis nearest to heading d: a square box has four.
(define (box-axis box d) (+ d (square-wrap (- (list-ref box 2) d))))

;; The point of the path the box steers for: lookahead mm along the path
;; past the point of it nearest the box, or the goal.
(define lookahead 700)
(define (aim-point box)
  (let loop ((legs box-path) (best #f) (best-d #f))
    (if (or (null? legs) (null? (cdr legs)))
        (along-path best (+ (leg-position box (car best) (cadr best)) lookahead))
        (let ((d (leg-distance box (car legs) (cadr legs))))
          (if (or (not best-d) (< d best-d))
              (loop (cdr legs) legs d)
              (loop (cdr legs) best best-d))))))

;; How far along the leg from a to b the point of it nearest p is, mm.
(define (leg-position p a b)
  (let ((len (distance a b)))
    (max 0 (min len (/ (+ (* (- (car p) (car a)) (- (car b) (car a)))
                          (* (- (cadr p) (cadr a)) (- (cadr b) (cadr a))))
                       len)))))

;; The point s mm along legs (a path from its first point); past its end,
;; on the last leg's line, so that the box near the goal still aims along
;; the path rather than at a point it is about to pass.
(define (along-path legs s)
  (let ((a (car legs)))
    (if (null? (cdr legs))
        a
        (let ((len (distance a (cadr legs))))
          (if (or (<= s len) (null? (cddr legs)))
              (let ((t (/ s len)))
                (list (+ (car a) (* t (- (car (cadr legs)) (car a))))
                      (+ (cadr a) (* t (- (cadr (cadr legs)) (cadr a))))))
              (along-path (cdr legs) (- s len)))))))

;;> The task: take places, then move the box, as start-steps runs it.
(define (box-move-task)
  (start-steps 'box-move
               (task-step (list '((mobile fiducial) ()) '((mobile fiducial) ())
                                '((fiducial) ()))
                          (list (location-metric-maker '(-2000 400 0 0))
                                (location-metric-maker '(-2000 -400 0 0))
                                (location-metric-maker '(0 2500 0 0)))
                          (list take-place take-place watch-place)
                          '(3 2 1) '(#t #t #f))
               ;; Negotiated again, by the places taken: the robots behind
               ;; the box win, and a pusher lost is replaced by the nearest
               ;; capable robot left.
               (task-step (list '((mobile fiducial) ()) '((mobile fiducial) ())
                                '(same 1 3))
                          (list (location-metric-maker '(-2040 170 0 0))
                                (location-metric-maker '(-2040 -170 0 0))
                                #f)
                          (list push push watch)
                          '(2 1 3) '(#t #t #f))))
