;;; A team moves a box along a path (thesis §1.2; MURDOCH 2002): two
;;; pushers push it from behind, and a watcher watches it with its
;;; fiducial finder and tells the pushers where it is.  No one reads where
;;; the box is in the simulator: the watcher sees it as a sensor would.
;;; Every place comes from the path (box-path.scm: box-path, box-side) and
;;; from what the robots see; nothing here knows the lab.
;;;
;;; (box-move-task) is the task: two steps, run by start-steps.
;;;   1. Take places: each pusher finds its way to its side behind the box,
;;;      the watcher turns to face the path's start.
;;;   2. Move the box: at the barrier push, the pushers start; the watcher
;;;      sends each its sighting of the box every 0.2 s; each pusher keeps
;;;      the box's heading on the path by pushing harder or softer on its
;;;      side; they stop when the box reaches the goal.
;;; The pushers' components may restart: a pusher that fails is replaced by
;;; a spare robot, which finds its way to the lost pusher's place at the box
;;; as the box is then, while the other pushes alone.

;;; Geometry

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

(define box-half (/ box-side 2))
(define body-radius 180)                ; a B14's
(define pusher-offset 170)              ; each pusher's offset from the centre line
(define face-gap 40)                    ; between a place and the box's face
(define push-speed 220)                 ; mm/s

;;; Time, by the robot's own clock

;; The team's control runs in rounds whose length the machine decides: a
;; loaded machine makes them longer, and the simulator keeps its own pace
;; against the wall clock.  So every wait and every "lately" here is in
;; seconds of the robot's own clock (robot-time), never a count of rounds,
;; and a motion command is bounded by the round it runs for (drive!).
(define now #f)                         ; this round's start, robot seconds
(define round-s 0.2)                    ; how long the last round took

;; Starts a round: reads the clock and how long the round before took.
(define (start-round!)
  (let ((t (robot-time)))
    (if now (set! round-s (clip (- t now) 0.05 2)))
    (set! now t)))

;; Sets the velocities, bounded so that a round as long as the last moves
;; the robot at most 100 mm and turns it at most 20 degrees before it looks
;; again: under load a command runs longer, on a view that grows staler.
(define (drive! speed turn)
  (set-velocity (clip speed (/ 100 round-s)) (clip turn (/ 20 round-s))))

;; Turns the robot in place to heading, unless it nearly faces it: a
;; rotation of a hundredth of a degree may never be seen to end, for the
;; simulator lets a body that barely turns fall asleep.
(define (turn-to! heading)
  (if (> (abs (wrap (- heading (list-ref (reckon) 2)))) 2)
      (rotate 'to heading)))

;; Turns toward heading within the round, at most 40 degrees a second:
;; not turn-to!'s rotation, which the round would wait for.
(define (turn-toward! heading)
  (drive! 0 (clip (* 2 (wrap (- heading (list-ref (reckon) 2)))) 40)))

;; The box as this robot sees it, (X Y HEADING) in the room, or #f.
(define (see-box)
  (let ((seen (fiducials)))
    (and (pair? seen)
         (let* ((f (car seen)) (me (reckon))
                (a (* degrees (+ (list-ref me 2) (fiducial-bearing f)))))
           (list (+ (car me) (* (fiducial-range f) (cos a)))
                 (+ (cadr me) (* (fiducial-range f) (sin a)))
                 (+ (list-ref me 2) (fiducial-orientation f)))))))

;; The distance from point p to the leg from a to b.
(define (leg-distance p a b)
  (let* ((dx (- (car b) (car a))) (dy (- (cadr b) (cadr a)))
         (t (/ (+ (* (- (car p) (car a)) dx) (* (- (cadr p) (cadr a)) dy))
               (+ (* dx dx) (* dy dy))))
         (t (max 0 (min 1 t))))
    (distance p (list (+ (car a) (* t dx)) (+ (cadr a) (* t dy))))))


;; Whether the box has reached the goal: near it, or past it along the
;; path's last leg and within 250 mm of that leg's line.
(define (arrived? box)
  (let ((off (goal-offsets box)))
    (or (< (distance box (goal)) 120)
        (and (>= (car off) -60) (< (abs (cadr off)) 250)))))

;; How far the box is past the goal along the last leg, and to its left.
(define (goal-offsets box)
  (let* ((g (goal)) (from (list-ref box-path (max 0 (- (length box-path) 2))))
         (d (* degrees (heading-to from g)))
         (dx (- (car box) (car g))) (dy (- (cadr box) (cadr g))))
    (list (+ (* dx (cos d)) (* dy (sin d))) (- (* dy (cos d)) (* dx (sin d))))))

;; Whether the box has gone past the goal wide of it: it cannot be pushed
;; back.
(define (passed-wide? box)
  (let ((off (goal-offsets box)))
    (and (>= (car off) -60) (>= (abs (cadr off)) 250))))

;; The place behind the box, pushing toward d degrees, offset mm to the
;; left of its centre line and back mm behind its centre (by default a
;; pusher's place, face-gap from the face).
(define (behind-at box d offset . back)
  (let ((back (if (pair? back) (car back) (+ box-half body-radius face-gap)))
        (a (* d degrees)))
    (list (- (+ (car box) (* offset (- (sin a)))) (* back (cos a)))
          (- (+ (cadr box) (* offset (cos a))) (* back (sin a))))))

;; The axis the box is pushed along: the one of its four nearest the
;; heading of the path's leg nearest it, so that a box turned or off the
;; path keeps its rear face; at a bend, the one it was, while that is
;; within 60 degrees of the new leg.
(define last-axis #f)
(define (place-axis box)
  (let* ((legs (nearest-legs box)) (leg (heading-to (car legs) (cadr legs)))
         (kept (and last-axis (box-axis box last-axis)))
         (axis (if (and kept (< (abs (wrap (- kept leg))) 60)) kept (box-axis box leg))))
    (set! last-axis axis)
    axis))

;; The path from the start of the leg nearest the box on.
(define (nearest-legs box)
  (let loop ((legs box-path) (best #f) (best-d #f))
    (if (null? (cdr legs))
        best
        (let ((d (leg-distance box (car legs) (cadr legs))))
          (if (or (not best-d) (< d best-d))
              (loop (cdr legs) legs d)
              (loop (cdr legs) best best-d))))))

;; Where the pusher on side (+1 left, -1 right) stands behind the box.
(define (place-of box side) (behind-at box (place-axis box) (* side pusher-offset)))

;; How far the point offset mm left of the box's middle, back mm behind it,
;; lies ahead of this robot along axis and to its left: (AHEAD LEFT).
(define (offsets-to box axis offset . back)
  (let* ((p (apply behind-at box axis offset back)) (me (reckon)) (a (* axis degrees))
         (dx (- (car p) (car me))) (dy (- (cadr p) (cadr me))))
    (list (+ (* dx (cos a)) (* dy (sin a))) (- (* dy (cos a)) (* dx (sin a))))))

;;; Roles and their metrics, from the path and the box's sighting

;; The path's first point, as a box heading along its first leg.
(define (path-start-box)
  (let ((p (car box-path)))
    (list (car p) (cadr p) (heading-to p (cadr box-path)))))

;; The side the path first turns to (+1 left, -1 right): the inside
;; pusher's.  Left for a straight path.
(define (inside-side)
  (let loop ((p box-path))
    (if (or (null? (cdr p)) (null? (cddr p)))
        1
        (let* ((a (car p)) (b (cadr p)) (c (car (cddr p)))
               (cross (- (* (- (car b) (car a)) (- (cadr c) (cadr b)))
                         (* (- (cadr b) (cadr a)) (- (car c) (car b))))))
          (cond ((> cross 1) 1) ((< cross -1) -1) (else (loop (cdr p))))))))

(define (role side) (if (= side (inside-side)) 'inside 'outside))

;; How far this robot is from the place of the pusher on side: at the box as
;; its fiducial finder sees it, or, seeing none, at the path's start.  The
;; pushers' metrics ask each candidate this, so that in step 2 the robots
;; at the places win them, and a spare is measured to the box as it is now.
(define (place-distance side)
  (distance (reckon) (place-of (or (see-box) (path-start-box)) side)))
(define (left-place-distance) (place-distance 1))
(define (right-place-distance) (place-distance -1))

;; How far this robot is from the middle of the path: the watcher's metric.
(define (path-middle-distance)
  (distance (reckon) (along-path box-path (/ (path-length box-path) 2))))

(define (path-length legs)
  (if (null? (cdr legs))
      0
      (+ (distance (car legs) (cadr legs)) (path-length (cdr legs)))))

(define (asking proc) (metric-by-asking proc (lambda (mm) mm)))

;;; The watcher

(define (watch-place previous)
  (turn-to! (heading-to (reckon) (car box-path)))
  (local-aspace-uid))

;; Tells the pushers where the box is, when it saw it (its own clock, the
;; simulator's, as every robot's), and where the bodies of lost pushers
;; lie (their last word of where they were), until the box has arrived;
;; keeps the box in view.
(define (watch previous)
  (team-barrier 'push 120)
  (start-round!)
  (reset-progress!)
  (let loop ((last #f) (where '()) (done 0) (began now))
    (start-round!)
    (let ((box (see-box)) (bodies (lost-bodies where)))
      (keep-in-view (or box last))
      (if box
          (for-each (lambda (uid) (if (not (eq? uid (local-aspace-uid)))
                                      (team-send! uid (list 'box box bodies now))))
                    (step-team)))
      (thread-sleep! 0.15)
      (let* ((heard (all-heard)) (box (or box last))
             (where (fold-at heard where))
             (done (+ done (count (lambda (h) (eq? (cdr h) 'done)) heard))))
        (cond ((or (>= done 2) (and (>= done 1) box (arrived? box))) (or box 'lost-sight))
              ;; A pusher that stalls says it is done and fails; one lost
              ;; says nothing: the watcher, too, stops when the box has
              ;; come no nearer its goal for longer than a pusher waits.
              ((and (stalled? (and box (path-to-go box)))
                    (> (- now progress-at) (+ stall-seconds 30)))
               (error (string-append "watch: the box came no nearer its goal in "
                                     (number->string (+ stall-seconds 30)) " s")
                      'box (and box (rounded box)) 'pushers-done done))
              ((> (- now began) 900) (error "watch: the pushers did not finish" done))
              (else (loop box where done began)))))))

;; Every message waiting, (FROM . VALUE) each.
(define (all-heard)
  (let ((heard (guard (e (#t #f)) (team-receive 0.01))))
    (if heard (cons heard (all-heard)) '())))

;; where, a list of (UID X Y T), with each pusher's newest (at X Y), heard
;; at T on the watcher's clock.
(define (fold-at heard where)
  (fold (lambda (h where)
          (if (and (pair? (cdr h)) (eq? (car (cdr h)) 'at))
              (cons (append (cons (car h) (cdr (cdr h))) (list now))
                    (remove (lambda (w) (eq? (car w) (car h))) where))
              where))
        where heard))

;; Where the pushers that left the team, or have not said where they are
;; for 3 s (a pusher says it every half second), were last: a pusher lost
;; with no spare to take its part stays in the team.
(define (lost-bodies where)
  (let ((team (step-team)))
    (map (lambda (w) (list (list-ref w 1) (list-ref w 2)))
         (filter (lambda (w) (or (not (memq (car w) team)) (> (- now (list-ref w 3)) 3)))
                 where))))

;; Turns toward the box when it nears the edge of the finder's view.
(define (keep-in-view box)
  (if box
      (let* ((me (reckon)) (bearing (wrap (- (heading-to me box) (list-ref me 2)))))
        (drive! 0 (if (< (abs bearing) 30) 0 (clip bearing 30))))))

;;; The pushers

;; The team as it is now: a spare may have replaced a pusher.
(define (my-side) (if (eq? (local-aspace-uid) (car (step-team))) 1 -1))

;; The other pusher, as the team was at the last look.
(define team '())
(define (partner) (list-ref team (if (eq? (local-aspace-uid) (car team)) 1 0)))

;; Finds its way to its place behind the box, as it sees the box (which
;; stays put meanwhile), on the side agreed with the other pusher.  Until
;; it first sees the box, the user's word stands in for a sighting: the box
;; starts at the path's start.  A sighting is checked before the robot
;; drives by it (sane-sighting?).  It counts itself at its place only by
;; a sighting at most a second old, but drives its planned way by one up to
;; sighting-kept seconds old, for a way round the box turns its finder away
;; from it (seed 4: a pusher that turned back to look each second, then
;; away to its way, turned to and fro for a minute); with none as fresh it
;; turns to where it last saw the box and looks again (look-for!).
;; It fails when it has come no nearer its place for stall-seconds.
(define (take-place previous)
  (sonar-start)
  (let* ((first (begin (start-round!) (see-box)))
         (side (agree-side (my-side) (or first (path-start-box)))))
    (start-round!)
    (reset-progress!)
    (let loop ((box (or first (path-start-box))) (seen-at (if first now -100)))
      (start-round!)
      (let* ((sighting (see-box))
             (ok? (and sighting (sane-sighting? sighting box seen-at)))
             (box (if ok? sighting box))
             (seen-at (if ok? now seen-at))
             (fresh? (< (- now seen-at) 1))
             (kept? (< (- now seen-at) sighting-kept)))
        (cond ((and fresh? (at-place? box (* side pusher-offset)))
               (stop-base)
               (turn-to! (place-axis box))
               (list (local-aspace-uid) (role side)))
              ((stalled? (and kept? (distance (reckon) (place-of box side))))
               (stop-base)
               (error (string-append "take-place: no nearer its place behind the box in "
                                     (number->string stall-seconds) " s: " held)
                      (local-aspace-uid) (rounded (reckon)) 'box (rounded box)
                      'place (rounded (place-of box side))))
              (else
               (if kept? (approach! (list box '()) (* side pusher-offset)) (look-for! box))
               (thread-sleep! 0.1)
               (loop box seen-at)))))))

;; How long, in seconds, a pusher taking its place drives by its last
;; sighting of the box, which no one pushes meanwhile.
(define sighting-kept 8)

;; Whether a sighting of the box may be driven by: it does not put the box
;; on this robot, and, after a sighting within the last 2 s, the box has
;; not leapt more than 300 mm since.  One that is not is looked at again,
;; and after 2 s the next is taken as it is, for the box may really have
;; been knocked away.
(define (sane-sighting? sighting last seen-at)
  (and (> (box-clearance (reckon) sighting) (- body-radius 60))
       (or (> (- now seen-at) 2) (< (distance sighting last) 300))))

;; How far point p lies outside the box's square: 0 inside it.
(define (box-clearance p box)
  (let* ((a (* (list-ref box 2) degrees))
         (dx (- (car p) (car box))) (dy (- (cadr p) (cadr box)))
         (u (max 0 (- (abs (+ (* dx (cos a)) (* dy (sin a)))) box-half)))
         (v (max 0 (- (abs (- (* dy (cos a)) (* dx (sin a)))) box-half))))
    (sqrt (+ (* u u) (* v v)))))

;; Looks for the box, last seen (or said to be) at box: turns to face it;
;; facing it and still not seeing it (another robot hides it, or it is out
;; of the finder's range), comes nearer it along a planned way, or, when
;; what it last saw puts the box on this robot, turns on to look about.
(define (look-for! box)
  (let* ((me (reckon)) (bearing (wrap (- (heading-to me box) (list-ref me 2)))))
    (cond ((> (abs bearing) 30)
           (set! held "it does not see the box, and turns to where it was last seen")
           (drive! 0 (clip (* 2 bearing) 40)))
          ((> (box-clearance me box) (- body-radius 60))
           (set! held "it does not see the box where it was last seen, and goes nearer")
           (approach! (list box '()) 0))
          (else
           (set! held "it does not see the box, and looks about")
           (drive! 0 30)))))

;; The pushers' sides: the one that stands further left of the box's axis
;; (as each sees the box) takes the left place, so that the two do not
;; cross each other's way to them, whichever the negotiation gave which.
;; Each tells the other where it stands; one that hears nothing within 60 s
;; keeps the side it was given.
(define (agree-side side box)
  (let* ((team (step-team))
         (other (if (eq? (local-aspace-uid) (car team)) (cadr team) (car team)))
         (me (reckon)) (a (* degrees (place-axis box)))
         (mine (- (* (- (cadr me) (cadr box)) (cos a)) (* (- (car me) (car box)) (sin a)))))
    (team-send! other (list 'left-of-axis mine))
    (let wait ((left 60))
      (let ((heard (and (> left 0) (guard (e (#t #f)) (team-receive left)))))
        (cond ((not heard) side)
              ((and (eq? (car heard) other) (pair? (cdr heard))
                    (eq? (cadr heard) 'left-of-axis))
               (let ((theirs (list-ref heard 2)))
                 (cond ((> mine theirs) 1) ((< mine theirs) -1) (else side))))
              (else (wait (- left 1))))))))

(define (rounded xs) (map (lambda (x) (exact (round x))) xs))

;;; No spinning: a robot that comes no nearer its end for stall-seconds of
;;; its own clock stops, and its part fails saying what held it.

(define stall-seconds 60)
(define best-to-go #f)                  ; mm still to go, the least so far
(define progress-at 0)                  ; when it last fell by 100 mm
(define held "")                        ; what holds the robot, in words

(define (reset-progress!)
  (set! best-to-go #f)
  (set! progress-at now)
  (set! held "nothing it could tell"))

;; Whether the robot has made no progress for stall-seconds: to-go (mm
;; still to go, or #f when it cannot tell this round) has not fallen 100 mm
;; below the least it was.
(define (stalled? to-go)
  (if (and to-go (or (not best-to-go) (< to-go (- best-to-go 100))))
      (begin (set! best-to-go to-go) (set! progress-at now)))
  (> (- now progress-at) stall-seconds))

;; How far the box still has to go along the path, mm.
(define (path-to-go box)
  (let ((legs (nearest-legs box)))
    (- (path-length legs) (leg-position box (car legs) (cadr legs)))))

;; Whether this robot stands at the place offset mm left of the middle of
;; the box's rear face, against it; with slack (mm: it stood there the
;; round before), whether it is still near enough to push from there, at
;; most slack aside: a pusher that has fallen further behind or aside comes
;; up again as a spare does (approach!), never sideways along the face.
(define (at-place? box offset . slack)
  (let ((off (offsets-to box (place-axis box) offset))
        (turn (abs (wrap (- (place-axis box) (list-ref (reckon) 2))))))
    (if (and (pair? slack) (car slack))
        (and (< -150 (car off) 250) (< (abs (cadr off)) (car slack)) (< turn 35))
        (and (< -120 (car off) 30) (< (abs (cadr off)) 70) (< turn 20)))))

;; How far aside of its place a pusher at the face may stand and still push
;; from there: 200 mm; 75 mm from a spot of its own (push-offset: alone,
;; or clearing a lost partner's body); 50 mm while its partner says it is on
;; its way to its place, for one further aside stands in the way into the
;; partner's place, 340 mm off, and holds there waiting for it (140 mm
;; aside, generated seed 13; 93 mm, back from a spot nearer the middle
;; where it cleared the lost one's body, seed 149, for 48 s).
(define (aside-slack)
  (cond (lone-at 75) ((spare-on-its-way?) 50) (else 200)))

;; What the pusher hears, on its own clock: when its partner last said it
;; was at the face ('here), and when it last said how far it still had to
;; come ((coming MM)); when the newest view came.
(define partner-here -100)
(define partner-coming -100)
(define partner-coming-mm #f)
(define spare-way-at -100)              ; when a spare last said it had a way
(define view-at -100)

;; How lately, in seconds, the partner said it was at the face, or coming.
(define (here-age) (- now partner-here))
(define (coming-age) (- now partner-coming))

;; The newest view the watcher sent, (BOX BODIES), or last when none came.
(define (latest last)
  (let ((heard (guard (e (#t #f)) (team-receive 0.03))))
    (if (not heard)
        last
        (let ((m (cdr heard)))
          (cond ((and (pair? m) (eq? (car m) 'box))
                 (set! view-at now)
                 (note-turn! (cadr m) (list-ref m 3))
                 (latest (cdr m)))
                ((eq? m 'here) (set! partner-here now) (latest last))
                ((and (pair? m) (eq? (car m) 'coming))
                 (set! partner-coming now)
                 (if (< (cadr m) 1e8) (set! spare-way-at now))
                 (set! partner-coming-mm (cadr m))
                 (latest last))
                (else (latest last)))))))

;; Each round a pusher at the box tells its partner it is there, and one
;; on its way how far it has to come (1e9 when it has no way: neither a
;; planned one nor a staging point it docks from).  A spare pushes only
;; once it is at the face; until then the other pushes alone (steer!).
(define (push previous)
  (team-barrier 'push 120)
  (sonar-start)
  (start-round!)
  (set! view-at now)
  (reset-progress!)
  (let ((watcher (list-ref (step-team) 2)) (side (my-side))
        (own (see-box)))
    (let loop ((view (latest (and own (list own '())))) (at-face? #f) (said -100))
      (start-round!)
      (let ((said (if (< (- now said) 0.5) said (begin (say-where! watcher) now)))
            (seen (fresh view)))
        (thread-sleep! 0.05)
        (let ((box (and seen (car seen))))
          (cond
           ((and box (arrived? box))
            (stop-base)
            (team-send! watcher 'done)
            (list (local-aspace-uid) (role side)))
           ((and box (passed-wide? box))
            (stop-base)
            (team-send! watcher 'done)
            (error (string-append "push: the box passed its goal "
                                  (number->string (exact (round (abs (cadr (goal-offsets box))))))
                                  " mm to its side, and cannot be pushed back")
                   (local-aspace-uid) 'box (rounded box)))
           ((stalled? (and box (team-to-go box side at-face?)))
            (stop-base)
            (team-send! watcher 'done)
            (error (string-append "push: the box came no nearer its goal in "
                                  (number->string stall-seconds) " s: "
                                  (what-holds box at-face?))
                   (local-aspace-uid) (rounded (reckon)) 'box (and box (rounded box))))
           ;; Seeing no box, and told of none lately: a spare far off looks
           ;; for it where it was last told of.
           ((not box)
            (if (and view (not at-face?)) (look-for! (car view)) (stop-base))
            (loop (latest view) at-face? said))
           (else
            (let ((offset (push-offset seen side)))
              (cond ((at-place? box offset (and at-face? (aside-slack)))
                     (team-send! (partner) 'here)
                     (set! backing #f)
                     (steer! seen side offset)
                     (loop (latest view) #t said))
                    (else
                     (team-send! (partner)
                                 (list 'coming (if (or waypoint docking)
                                                   (distance (reckon) (place-of box side))
                                                   1e9)))
                     (approach! seen offset)
                     (loop (latest view) #f said)))))))))))

;; How far the team still has to go, mm, for the watchdog (stalled?): the
;; box along its path, this pusher to its place while it is not at the
;; face, and a spare on its way to its own, as it last said.
(define (team-to-go box side at-face?)
  (+ (path-to-go box)
     (if at-face? 0 (distance (reckon) (place-of box side)))
     (if (spare-on-its-way?) partner-coming-mm 0)))

;; What holds a pusher whose box has come no nearer its goal, in words.
(define (what-holds box at-face?)
  (cond ((not box) "neither this pusher nor the watcher sees the box")
        ((not at-face?)
         (string-append (if waypoint
                            "this pusher cannot come up to its place at the box"
                            "this pusher finds no way to its place at the box")
                        (turned-words box)))
        ((> (abs (turn-error box)) 45)
         (string-append "the box is turned away from its way" (turned-words box)))
        ((spare-on-its-way?) "it holds for its partner (or a spare), which does not come up")
        ((alone?) "it pushes alone: its partner was lost and no spare took its place")
        (else "the box does not move as it is pushed")))

;; How far the box must turn to head for its path, in words.
(define (turned-words box)
  (string-append " (it must turn " (number->string (exact (round (turn-error box))))
                 " degrees to head for its path)"))

;; Tells the watcher where this pusher is, and looks at who is in the team.
(define (say-where! watcher)
  (let ((me (reckon)))
    (set! team (step-team))
    (team-send! watcher (list 'at (car me) (cadr me)))))

;; The watcher's view, while it is at most a second old and does not put
;; the box on this robot; else this robot's own sighting of the box, with
;; the bodies last told, which the box's turn rate is then measured by
;; (seed 21: the watcher lost the box beyond its finder's range, and the
;; pair steered by the turn it last measured, turning the box on round past
;; its way); else #f: a pusher does not push on a view older than that,
;; however slow the round.
(define (fresh view)
  (if (and view (< (- now view-at) 1)
           (> (box-clearance (reckon) (car view)) (- body-radius 60)))
      view
      (let ((own (see-box)))
        (and own
             (begin (note-turn! own now)
                    (list own (if view (cadr view) '())))))))

;; How many degrees left the box must turn to head for the path: for its
;; aim point, but at most max-approach off the path's own way there, so
;; that a box far aside of its path is never steered toward a face its
;; pushers are not at (seed 42: a lone pusher left it 620 mm aside, the
;; pair turned it 45 degrees off its leg toward the path and past).
(define max-approach 30)
(define (turn-error box)
  (let* ((legs (nearest-legs box))
         (s (leg-position box (car legs) (cadr legs)))
         (aim (along-path legs (+ s lookahead)))
         (way (heading-to (along-path legs s) aim)))
    (wrap (- (+ way (clip (wrap (- (heading-to box aim) way)) max-approach))
             (place-axis box)))))

;; Where on the rear face this pusher pushes from, mm left of its middle:
;; its own place until it is alone; then the clear spot nearest lone-want, kept
;; until that has moved by more than 80 mm, for a pusher that slides far
;; along a face it pushes drags the box round the wrong way: it comes up
;; afresh to each new spot (approach!).  Before it is alone a spare may
;; come to the other half, and a lone pusher that slid toward the middle
;; as it pushed turned the box 45 degrees the wrong way in 5 s while the
;; spare waited for the lost pusher's body to clear its place (generated
;; seed 13).  A pusher whose own place a body holds pushes from the spot
;; of its own half nearest it that is clear, out to where half of it is
;; behind the face: seed 42's box turned until the lost pusher's body lay
;; behind its middle, holding both places, and no one pushed it on.
;; A pusher that pushed in a pair and has lost its partner, with no spare
;; saying it has a way to its place (the lost one's body holds it), pushes
;; until one has from the spot of its own half nearest lone-want (the
;; middle, when the box must turn toward the other half) that is clear of
;; the bodies and has a staging point, chosen afresh when that has moved by
;; more than 80 mm: from its own place, beside the body, its push turned
;; the box about the body's corner away from its side, 20 to 35 degrees the
;; wrong way in the 300 mm that clear the body (generated seeds 38 and 160,
;; the outside pusher lost before a bend to the inside; the pair then had
;; to turn the box 60 to 100 degrees at the bend and passed its goal wide).
;; Chosen once, nearest the middle, the spot still let the box turn 20 to
;; 34 degrees the wrong way (seeds 160, 149).  Not on the other half: there
;; the spare comes, and seed 149's lone pusher went round to it and stood
;; in the spare's way.  A spare, which has not pushed in a pair, never
;; takes that spot: its place is the lost one's.  A pusher whose own place
;; a body holds takes a spot that leaves its partner's place free (the
;; width of a robot from it): seed 149's spare, the body at its place,
;; chose a spot 50 mm from the middle of a 410 mm box, where the lone
;; pusher's edge stood in its way in, and each held for the other.
(define lone-at #f)
(define (push-offset view side)
  (let ((own (* side pusher-offset)) (box (car view)) (bodies (cadr view)))
    (cond ((alone?)
           (let ((want (or (clear-offset box bodies side (lone-want box) pusher-offset) own)))
             (cond ((not lone-at) (set! lone-at own))
                   ((> (abs (- want lone-at)) 80) (set! lone-at want)))
             lone-at))
          ((and (pair? bodies) paired-at (not (paired?)) (>= (- now spare-way-at) 1))
           (let ((o (clear-offset box bodies side (lone-want box) (+ box-half (/ body-radius 2)) side)))
             (if (and o (or (not lone-at) (> (abs (- o lone-at)) 80))
                      (staging box (place-axis box) o bodies))
                 (set! lone-at o))
             (or lone-at (begin (set! lone-at own) own))))
          (else
           (set! lone-at #f)
           (or (clear-offset box (cons (behind-at box (place-axis box) (- own)) bodies)
                             side own (+ box-half (/ body-radius 2)) side)
               own)))))

;; Whether this pusher has heard nothing from a partner for 10 s (long
;; enough for a spare to be found and the watcher to know where the lost
;; one lies): its partner was lost and no spare took its part.
(define (alone?) (and (>= (here-age) 10) (>= (coming-age) 10)))

;; Whether the partner said lately (within 0.8 s) that it is at the face.
(define (paired?) (< (here-age) 0.8))

;; Two pushers stand pusher-offset to either side of the middle, and the
;; box turns toward the path when the one on the far side of the turn
;; pushes harder (pair-share).  A pusher alone (its partner has not said
;; lately that it is at the face) pushes from the spot push-offset gives
;; (its own place, or one nearer the middle while it clears a lost
;; partner's body), slanted in as lone-push! says; it holds
;; while the box turns faster than max-turn-rate, and once a spare has a
;; way to the other place, leaving that free.  Before a spare speaks it
;; pushes on only until the box has left the lost partner's body behind,
;; and then only while its push turns the box toward its way (lone-push?).
(define (steer! view side offset)
  (let* ((box (car view))
         (share (cond ((paired?) (pair-share box side))
                    ((spare-on-its-way?) 0)
                    ((> (abs turn-rate) max-turn-rate) 0)
                    ((lone-push? box side) 0.5)
                    (else 0))))
    (if (paired?) (set! paired-at box))
    (if (or (paired?) (alone?) (= share 0))
        (push-at! box (place-axis box) offset share)
        (lone-push! box offset share))))

;; Pushes at share of push-speed from where this pusher stands at the face,
;; offset mm left of its middle, heading off the box's axis toward the
;; middle by lone-slant degrees at a place's offset (less nearer it), and only
;; while it heads so (within 6 degrees), else turning there first.  A push
;; off the middle turns the box away from the pusher's side; the pusher,
;; pressed to the face, turns with the box and lags it, heading out, and the
;; face sliding on its front then turns the box further the same way: the
;; lone pusher of generated seed 13, steering back to its place as it
;; pushed, headed 13 to 19 degrees out and turned the box 6 degrees a
;; second the wrong way.  Slanted in, that slide turns the box back.
(define lone-slant 10)
(define (lone-push! box offset share)
  (let* ((axis (place-axis box))
         (want (- axis (clip (* lone-slant (/ offset pusher-offset)) lone-slant)))
         (turn (wrap (- want (list-ref (reckon) 2)))))
    (drive! (if (< (abs turn) 6) (* push-speed (slowing box) share) 0)
            (clip (* 2 turn) 40))))

;; Whether a pusher whose partner is not at the face pushes: alone, or
;; while a spare waits for a lost pusher's body to clear its place (so
;; that it may come); else, until a spare speaks, only while the box is
;; still within clear-run of where it was when the two last pushed
;; together, so that it leaves the lost partner's body behind and the
;; spare finds that place clear sooner, or while its push turns the box
;; toward its way: a
;; push off the middle turns the box away from the pusher's side, so while
;; the box must turn that way by more than 3 degrees, what it will turn
;; within turn-lead at its rate now counted.  One that pushed on, sliding
;; toward the middle, turned the box 15 to 30 degrees the wrong way before
;; the spare came (generated seeds 13 and 38, the box to turn toward the
;; lone pusher's side), and the pair could not bring it back by the goal.
(define paired-at #f)                   ; the box when last pushed by two
(define clear-run (+ body-radius body-radius 40))
(define (lone-push? box side)
  (or (alone?)
      (spare-spoke?)
      (and paired-at (< (distance box paired-at) clear-run))
      (< (* side (- (clip (turn-error box) 20) (* turn-lead turn-rate))) -3)))

;; A pusher's share of push-speed in a pair: both push less the further
;; the box is turned off its way (forward at a quarter from 34 degrees off),
;; so that it turns more than it goes; and one pushes more and the other
;; less, by the difference of speed that turns the box, held between two
;; pushers pusher-offset either side of its middle, at the rate wanted:
;; pair-gain a second of how far it must turn, up to pair-rate, plus
;; rate-feedback of what the rate it turns now falls short of that.  Two
;; pushers hold the box to the speeds they drive at, so a pair turns it at
;; nearly the rate their speeds say; steered by how far it must turn less
;; what it would turn in 1.5 s at the rate last seen, a pair of generated
;; seed 160 or 38 turned its box at 30 degrees a second to and fro, some
;; 10 degrees either side, each half second or so that the views came,
;; knocking its pushers off their places (seed 38's spare was off the
;; face for half the last third).  The slower pushes at no less
;; than 0.1 of its speed: held at 0.3, a pair with its box 100 degrees off
;; turned it at 7 degrees a second and drifted 600 mm past a bend.
(define turn-lead 1.5)                  ; seconds ahead, for a pusher alone (lone-push?)
(define max-turn-rate 8)                ; degrees a second, for a pusher alone
(define pair-gain 0.5)                  ; per second
(define pair-rate 20)                   ; degrees a second
(define rate-feedback 0.5)
(define (pair-share box side)
  (let* ((err (turn-error box))
         (want (clip (* pair-gain err) pair-rate))
         (rate (+ want (* rate-feedback (- want turn-rate)))))
    (clip (- (clip (- 1 (/ (abs err) 45)) 0.25 1)
             (/ (* side rate degrees pusher-offset) push-speed))
          0.1 1.6)))

;; How fast the box turns, degrees a second, left positive, from the
;; sightings it pushes by (fresh), at least rate-span seconds apart by the
;; clock they were seen at (the watcher's, or this robot's for its own: one
;; clock, the simulator's), not by when a view arrived: a view a round
;; late, or two in one round, made a rate of twice or half the true one;
;; a sighting older than the last is passed over.
(define turn-rate 0)
(define rate-span 0.5)
(define rate-from #f)                   ; (SECONDS HEADING)
(define (note-turn! box seen-at)
  (let ((h (list-ref box 2)))
    (cond ((not rate-from) (set! rate-from (list seen-at h)))
          ((>= (- seen-at (car rate-from)) rate-span)
           (set! turn-rate
                 (/ (square-wrap (- h (cadr rate-from))) (- seen-at (car rate-from))))
           (set! rate-from (list seen-at h))))))

;; Whether a spare said lately (within 2 s) that it has a way to its place.
(define (spare-on-its-way?)
  (and (< (coming-age) 2) (< partner-coming-mm 1e8)))

;; Whether a spare said lately (within 2 s) how far it has to come, with a
;; way or none (a lost pusher's body at its place, which the lone pusher's
;; push clears).
(define (spare-spoke?) (< (coming-age) 2))

;; Where a pusher alone would push, mm left of the middle of the rear
;; face: 10 mm aside a degree the box must turn, to the right of the middle
;; to turn it left.
(define (lone-want box) (clip (* -10 (turn-error box)) pusher-offset))

;; The spot nearest want, mm left of the middle of the rear face, its own
;; side first, that is clear of the lost pushers' bodies as a place must be
;; (staging), at most reach from the middle and, given half, on that side
;; of it (+1 left, -1 right); #f when there is none.
(define (clear-offset box bodies side want reach . half)
  (let* ((axis (place-axis box))
         (clear? (lambda (o)
                   (and (<= (abs o) reach)
                        (or (null? half) (>= (* o (car half)) 0))
                        (clear-of? bodies (list (behind-at box axis o)) -40)))))
    (let loop ((k 0))
      (cond ((> k (* 2 reach)) #f)
            ((find clear? (list (+ want (* side k)) (- want (* side k)))))
            (else (loop (+ k 20)))))))

;; Whether every point is a robot's width and a margin (20 mm, or the one
;; given: a spare may nudge a body at its place) from every body.
(define (clear-of? bodies points . margin)
  (let ((room (+ body-radius body-radius (if (pair? margin) (car margin) 20))))
    (every (lambda (b) (every (lambda (p) (> (distance b p) room)) points))
           bodies)))

;; Pushes at share of push-speed at the place offset mm left of the middle
;; of the box's rear face, hurrying when it has fallen behind it.
(define (push-at! box axis offset share)
  (let ((off (offsets-to box axis offset)))
    (drive-along! axis (car off) (cadr off)
                  (* push-speed (slowing box) (+ share (clip (/ (car off) 100) 0 1))))))


;; Sets the velocities that bring the robot, heading along axis, to a
;; point ahead and left of it (mm, in the axis's frame): forward at speed,
;; turning toward the point, or back when it is well behind.
;; It moves only as far as it faces along the axis (facing), for a robot
;; well off the axis that drives on leaves the way into its place sideways.
(define (drive-along! axis ahead left speed)
  (let ((turn (wrap (- (+ axis (clip (* 0.15 left) 25)) (list-ref (reckon) 2)))))
    (drive! (* (facing (- axis (list-ref (reckon) 2)))
               (if (< ahead -80) (max -200 (* 2 ahead)) speed))
            (clip (* 2 turn) 40))))

;; How much of its speed a robot turn degrees off its way may drive at:
;; all of it straight on, none from 60 degrees off.
(define (facing turn) (max 0 (- (* 2 (cos (* (wrap turn) degrees))) 1)))

;; Sets the velocities that bring the robot to point p; it turns in place
;; first.
(define (drive-to! p)
  (let* ((me (reckon)) (turn (wrap (- (heading-to me p) (list-ref me 2)))))
    (drive! (* (min 300 (* 2 (distance me p))) (facing turn)) (clip (* 2 turn) 60))))

;;; Finding a way to the place

;; Comes to the place offset mm left of the middle of the rear face of the
;; box of view, (BOX BODIES): along a planned way (plan-way) to a staging
;; point, then into the place: along the box's axis from a point behind it,
;; or, when a body lies right behind the place, along the face from a point
;; beside it, turning in place there.  A robot counts itself at a staging
;; point within stage-reach of it, and once docking beside the place it
;; keeps on while it is no further from the place than the staging point
;; and stage-reach: the spare of generated seed 13, its fault drawn,
;; stopped 52 mm past its staging point, 502 mm from its place, where it
;; neither docked (within 500 mm) nor planned a way on, and stood for 60 s.
;; Along the axis it never presses on into the face off its place: within
;; 30 mm of its place's line it stands and turns to the axis, and, 70 mm
;; or more aside, backs off to 200 mm behind and comes in again, turning
;; toward the place's line as if to a point 380 mm ahead (seed 160's
;; pusher, turning by drive-along!'s 0.15 degrees a mm, came in 70 to 100
;; mm aside again and again).  Put off its place by its partner's coming,
;; one pressed on into the face's corner at 120 mm/s for 5 to 12 s,
;; unsteered, and turned the box 6 to 8 degrees a second past its last
;; leg (generated seeds 160 and 13, faults drawn).
(define stage-back 450)
(define stage-out 450)                  ; a staging point beside the place
(define stage-reach 150)
(define docking #f)             ; the staging point reached, while docking
(define backing #f)             ; backing off the face, to come in again
(define waypoint #f)

(define planned-at -100)
(define (approach! view offset)
  (let* ((box (car view)) (axis (place-axis box))
         (off (offsets-to box axis offset)) (place (behind-at box axis offset))
         (stage (staging box axis offset (cadr view))))
    (if (and stage (or (< (distance (reckon) (car stage)) stage-reach)
                       (and (eq? (cdr stage) 'behind) (in-corridor? off 1))))
        (set! docking (cdr stage)))
    (cond ((and (eq? docking 'behind) (in-corridor? off 2) (blocked-ahead? box axis place))
           (set! held "something stands in its way into its place")
           (turn-toward! axis))
          ((and (eq? docking 'behind) (in-corridor? off 2))
           (set! held "it does not come into its place along the box's axis")
           (set! backing (if backing
                             (< (car off) 200)
                             (and (< (car off) 30) (>= (abs (cadr off)) 70))))
           (cond (backing (drive-along! axis (car off) 0 -120))
                 ((< (car off) 30) (turn-toward! axis))
                 (else (drive-along! axis (car off) (* (cadr off) (max 1 (/ 380 (max 100 (car off)))))
                                     (clip (* 1.5 (car off)) 120 300)))))
          ((and (eq? docking 'beside) (< (distance (reckon) place) (+ stage-out stage-reach)))
           (set! held "it does not come into its place along the box's face")
           (set! backing #f)
           (if (> (distance (reckon) place) 40)
               (drive-to! place)
               (turn-toward! axis)))
          (else
           (set! docking #f)
           (set! backing #f)
           (if (or (not waypoint) (>= (- now planned-at) 0.8))
               (begin (set! planned-at now)
                      (set! waypoint (and stage (plan-way (car stage) box (cadr view))))))
           (set! held (cond ((not stage) "a lost pusher's body lies at its place")
                            (waypoint "it drives the way it plans and comes no nearer")
                            (else "it finds no way to its place past the box and what its sonar hears")))
           (if waypoint (drive-to! waypoint) (stop-base))))))

;; Whether the sonar hears something other than the box in the way into
;; the place along axis: within 150 mm ahead of the robot's body and 100
;; mm of the place's line, wherever across its cone the echo came from,
;; where another robot would be pushed into the box.  The other pusher at
;; its own place, 340 mm aside, is not in it (seed 13: its edge, 160 mm
;; aside, read at a cone's middle, held the robot there for a minute).
(define (blocked-ahead? box axis place)
  (let ((me (reckon)) (a (* axis degrees)))
    (define (in-way? e)
      (let ((ahead (+ (* (- (car e) (car me)) (cos a)) (* (- (cadr e) (cadr me)) (sin a))))
            (aside (- (* (- (cadr e) (cadr place)) (cos a))
                      (* (- (car e) (car place)) (sin a)))))
        (and (< 0 ahead (+ body-radius 150)) (< (abs aside) 100))))
    (any (lambda (e) (every in-way? e)) (echoes me box))))

;; Whether a robot off (AHEAD LEFT) from its place may drive straight into
;; it along the box's axis: behind it, and the nearer the face the nearer
;; the place's line, lest it come sideways into the face or its corner.
;; A robot already on its way in keeps to it in a corridor twice as wide
;; (width 2, not 1): it turns to the axis before it drives (drive-along!),
;; and one that fell out of a corridor it had only just entered turned back
;; toward its staging point, and to and fro.
(define (in-corridor? off width)
  (and (< -150 (car off) (+ stage-back 200))
       (< (abs (cadr off)) (* width (+ 50 (* 1/3 (max 0 (car off))))))))

;; Where to come up to the place offset mm left of the middle from, as
;; (POINT . behind) or (POINT . beside): stage-back mm behind it, or
;; nearer, or out to its side, whichever first is clear of the bodies and
;; of what else the sonar hears (a wall behind the box: the echoes of a
;; body are the body's, whose margin is clear-of?'s); beside it, stage-out
;; mm out, when a body lies right behind it.  #f when the place itself is
;; not clear.
(define (staging box axis offset bodies)
  (let ((out (if (< offset 0) -1 1)) (heard (echoes (reckon) box)))
    (define (clear p kind)
      (and (clear-of? bodies (list p))
           (every (lambda (e) (or (not (echo-near? e p (+ body-radius 60)))
                                  (not (clear-of? bodies (list (car e)) -150))))
                  heard)
           (cons p kind)))
    (and (clear-of? bodies (list (behind-at box axis offset)) -40)
         (or (any (lambda (back)
                    (clear (behind-at box axis offset
                                      (+ box-half body-radius face-gap back))
                           'behind))
                  (list stage-back (- stage-back 100) (- stage-back 200)))
             (clear (behind-at box axis (+ offset (* out stage-out))) 'beside)))))

;; A point some 400 mm along a shortest way from here to goal, on a grid of
;; cells 100 mm square, that keeps clear of the box, of the bodies (X Y)
;; and of what the sonar echoes; #f when there is none.  goal has been
;; found clear (staging): its own cell, as start's, may be marked.
(define cell 100)
(define (plan-way goal box bodies)
  (let* ((me (reckon)) (margin 2500)
         (x0 (- (min (car me) (car goal)) margin))
         (y0 (- (min (cadr me) (cadr goal)) margin))
         (nx (cells-across (car me) (car goal) margin))
         (ny (cells-across (cadr me) (cadr goal) margin))
         (blocked (make-vector (* nx ny) #f))
         (cell-of (lambda (p) (+ (exact (round (/ (- (car p) x0) cell)))
                                 (* nx (exact (round (/ (- (cadr p) y0) cell))))))))
    ;; Marks the cells within r of p blocked; given 'free, free; given a
    ;; predicate, blocked those whose middle it holds for, leaving the others.
    (define (paint! p r . how)
      (let ((i0 (exact (round (/ (- (car p) x0) cell))))
            (j0 (exact (round (/ (- (cadr p) y0) cell))))
            (k (exact (ceiling (/ r cell)))))
        (do ((i (- i0 k) (+ i 1))) ((> i (+ i0 k)))
          (do ((j (- j0 k) (+ j 1))) ((> j (+ j0 k)))
            (if (and (< -1 i nx) (< -1 j ny)
                     (<= (* cell cell (+ (square (- i i0)) (square (- j j0)))) (* r r)))
                (cond ((null? how) (vector-set! blocked (+ i (* nx j)) #t))
                      ((eq? (car how) 'free) (vector-set! blocked (+ i (* nx j)) #f))
                      (((car how) (list (+ x0 (* cell i)) (+ y0 (* cell j))))
                       (vector-set! blocked (+ i (* nx j)) #t))))))))
    (paint-box! paint! box)
    ;; A body said to lie where this robot stands has been pushed away.
    (for-each (lambda (b) (if (> (distance b me) (+ body-radius body-radius))
                              (paint! b (+ body-radius body-radius))))
              bodies)
    (for-each (lambda (e)
                (paint! (car e) (+ body-radius 80)
                        (lambda (p) (echo-near? e p (+ body-radius 80)))))
              (echoes me box))
    ;; A robot hemmed in, by the box's grown edge or a robot beside it, may
    ;; still step out.
    (paint! me 150 'free)
    (let ((start (cell-of me)) (end (cell-of goal)))
      (let ((from (breadth-first blocked nx ny end start)))
        (and from
             (let follow ((c start) (k 4))
               (if (or (= k 0) (= c end))
                   (list (+ x0 (* cell (modulo c nx))) (+ y0 (* cell (quotient c nx))))
                   (follow (vector-ref from c) (- k 1)))))))))

;; The cells from a to b and margin beyond each.
(define (cells-across a b margin)
  (+ 1 (exact (ceiling (/ (+ (abs (- a b)) margin margin) cell)))))

;; Marks the box, grown by a body's radius and a margin, with paint!.
(define (paint-box! paint! box)
  (let* ((a (* (list-ref box 2) degrees)) (reach (+ box-half body-radius 60)))
    (do ((u (- reach) (+ u (/ cell 2)))) ((> u reach))
      (do ((v (- reach) (+ v (/ cell 2)))) ((> v reach))
        (paint! (list (+ (car box) (* u (cos a)) (* v (- (sin a))))
                      (+ (cadr box) (* u (sin a)) (* v (cos a))))
                0)))))

;; The sonar's echoes within 2.5 m of the ring, less those of the box
;; itself, each as the points in the room where its cone's middle and edges
;; (sonar-half-cone either side) reach: (MIDDLE EDGE EDGE).  A sonar says how
;; far the nearest thing in its cone is, not where across it: a wall seen
;; aslant echoes from the cone's edge, some 0.2 of the range off its middle
;; (seed 4: a wall 350 mm from the staging points read as 50 mm, and the
;; pusher found none clear).
(define sonar-half-cone 12.5)           ; a B14's sonar, degrees

;; Whether the echo e says something lies within r of p: wherever across
;; its cone it came from, for a far echo may have come from either edge.
(define (echo-near? e p r)
  (every (lambda (q) (< (distance q p) r)) e))

(define (echoes me box)
  (let ((a (* (list-ref box 2) degrees)))
    (let loop ((i 0) (ranges (sonar-read)) (out '()))
      (if (null? ranges)
          out
          (let* ((r (+ (car ranges) body-radius))   ; the ring is at the body's edge
                 (t (* degrees (+ (list-ref me 2) (* i 22.5))))
                 (at (lambda (t) (list (+ (car me) (* r (cos t))) (+ (cadr me) (* r (sin t))))))
                 (p (at t))
                 (dx (- (car p) (car box))) (dy (- (cadr p) (cadr box)))
                 (in-box? (and (< (abs (+ (* dx (cos a)) (* dy (sin a))))
                                  (+ box-half 150))
                               (< (abs (- (* dy (cos a)) (* dx (sin a))))
                                  (+ box-half 150)))))
            (loop (+ i 1) (cdr ranges)
                  (if (or (> (car ranges) 2500) in-box?)
                      out
                      (cons (list p (at (- t (* sonar-half-cone degrees)))
                                  (at (+ t (* sonar-half-cone degrees))))
                            out))))))))

;; Each cell's next cell on a shortest way to end, by a breadth-first
;; search from end over free cells and their eight neighbours, until it
;; reaches start; #f when it does not.
(define (breadth-first blocked nx ny end start)
  (let ((from (make-vector (* nx ny) #f)) (queue (make-vector (* nx ny) 0)))
    (vector-set! from end end)
    (vector-set! queue 0 end)
    (let loop ((head 0) (tail 1))
      (cond ((vector-ref from start) from)
            ((= head tail) #f)
            (else
             (let* ((c (vector-ref queue head)) (i (modulo c nx)) (j (quotient c nx)))
               (let next ((ds '((1 0) (-1 0) (0 1) (0 -1) (1 1) (1 -1) (-1 1) (-1 -1)))
                          (tail tail))
                 (if (null? ds)
                     (loop (+ head 1) tail)
                     (let* ((i2 (+ i (car (car ds)))) (j2 (+ j (cadr (car ds))))
                            (c2 (+ i2 (* nx j2))))
                       (if (and (< -1 i2 nx) (< -1 j2 ny) (not (vector-ref from c2))
                                (or (= c2 start) (not (vector-ref blocked c2))))
                           (begin (vector-set! from c2 c)
                                  (vector-set! queue tail c2)
                                  (next (cdr ds) (+ tail 1)))
                           (next (cdr ds) tail)))))))))))

(define (clip x lo . hi)
  (if (pair? hi) (max lo (min (car hi) x)) (max (- lo) (min lo x))))

;; Full speed, down to a third within the last 600 mm, so that the box
;; does not slide past the goal.
(define (slowing box) (clip (/ (distance box (goal)) 600) 0.33 1))

;; The box's axis nearest to heading d: a square box has four.
(define (box-axis box d) (+ d (square-wrap (- (list-ref box 2) d))))

;; How far along the path, past the point of it nearest the box, the
;; point the box steers for lies, mm (turn-error).
(define lookahead 700)

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
                          (list (asking left-place-distance) (asking right-place-distance)
                                (asking path-middle-distance))
                          (list take-place take-place watch-place)
                          '(3 2 1) '(#t #t #f))
               ;; Negotiated again by the same metrics: the robots at the
               ;; places just taken win, and a pusher lost is replaced by the
               ;; capable robot left nearest its place at the box as it is.
               (task-step (list '((mobile fiducial) ()) '((mobile fiducial) ())
                                '(same 1 3))
                          (list (asking left-place-distance) (asking right-place-distance)
                                #f)
                          (list push push watch)
                          '(2 1 3) '(#t #t #f))))
