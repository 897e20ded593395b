;;; tools/chibi tools/box-layout.scm SEED DIR [CODE-FILE]: a box-moving lab
;;; drawn from SEED, written as DIR/lab.scm and DIR/path.scm, or refused.
;;;
;;; A walled room, 8 to 10 m by 6 to 8 m; a square box 400 to 800 mm a side,
;;; 3 to 12 kg, somewhere in it, turned up to 15 degrees off its path; a
;;; path of 2 or 3 legs of 1 to 3 m, each bend 20 to 60 degrees left or
;;; right; four robots (two become pushers, one the watcher, one the
;;; spare: the negotiation chooses), each behind, beside or ahead of the box,
;;; near (1 to 1.8 m) or far (2.2 to 3.8 m), facing any way.  The lab's code
;;; is DIR/path.scm (the path and the box's side: what a user tells the task)
;;; and CODE-FILE (default examples/box-move.scm), named by its absolute path.
;;;
;;; Prints `box-layout: seed N: ...`, the layout in words, and `box-layout:
;;; fault ROLE after S s` (the pusher a fault run kills, and when, in wall
;;; seconds after the first step is done, while the box is in the first
;;; half of its way; drawn after the layout, so a fault never changes it);
;;; exits 0.  A layout the team cannot do is refused:
;;; `box-layout: seed N: refused: REASON`, exit 3, and nothing is written.
(import (scheme base) (scheme write) (scheme inexact) (scheme file)
        (scheme process-context) (scheme cxr) (srfi 1)
        (only (chibi filesystem) current-directory create-directory*))

;;; A generator of its own, the same on every machine and Chibi: a 48-bit
;;; linear congruential one (drand48's constants).

(define state 0)
(define (seed! n)
  (set! state (modulo (+ (* n 2654435761) 1013904223) 281474976710656))
  (draw!) (draw!))
(define (draw!)
  (set! state (modulo (+ (* state 25214903917) 11) 281474976710656))
  (/ (quotient state 65536) 4294967296.))
(define (uniform lo hi) (+ lo (* (- hi lo) (draw!))))
(define (pick items) (list-ref items (exact (floor (* (draw!) (length items))))))

;;; Geometry, millimetres and degrees

(define degrees (/ (acos -1) 180))
(define (towards p heading mm)
  (list (+ (car p) (* mm (cos (* heading degrees))))
        (+ (cadr p) (* mm (sin (* heading degrees))))))
(define (distance p q)
  (sqrt (+ (square (- (car p) (car q))) (square (- (cadr p) (cadr q))))))
(define (heading-to p q)
  (/ (atan (- (cadr q) (cadr p)) (- (car q) (car p))) degrees))
(define (wrap a) (- a (* 360 (round (/ a 360)))))

;; The distance from p to the segment a-b.
(define (segment-distance p a b)
  (let* ((dx (- (car b) (car a))) (dy (- (cadr b) (cadr a)))
         (t (/ (+ (* (- (car p) (car a)) dx) (* (- (cadr p) (cadr a)) dy))
               (+ (* dx dx) (* dy dy)))))
    (distance p (towards a (heading-to a b) (* (max 0 (min 1 t)) (distance a b))))))

(define (path-distance p path)
  (apply min (map (lambda (a b) (segment-distance p a b))
                  (drop-right path 1) (cdr path))))

(define wall-thickness 50)
(define radius 180)                     ; a B14's
(define (round-mm x) (exact (round x)))

;; How far p is inside the room of half-width w and half-depth d, to the
;; walls' faces; negative outside.
(define (clearance p w d)
  (- (min (- w (abs (car p))) (- d (abs (cadr p)))) (/ wall-thickness 2)))

;;; A layout

(define robot-names
  '(ada brno cato dido egon fay gus hal ines jory kai lune mira nils oda pim))

(define (draw-layout)
  (let* ((w (exact (* 50 (round (/ (uniform 4000 5000) 50)))))
         (d (exact (* 50 (round (/ (uniform 3000 4000) 50)))))
         (side (exact (* 10 (round (/ (uniform 400 800) 10)))))
         (mass (/ (round (* 10 (uniform 3 12))) 10))
         ;; Anywhere a metre or more from the walls, the path setting out
         ;; toward the room's middle, give or take 60 degrees.
         (box (list (round-mm (uniform (- 1000 w) (- w 1000)))
                    (round-mm (uniform (- 1000 d) (- d 1000)))))
         (first-heading (+ (heading-to box (list (uniform (- 1500 w) (- w 1500))
                                                 (uniform (- 1000 d) (- d 1000))))
                           (uniform -60 60)))
         (legs (if (< (draw!) 0.5) 2 3))
         (bends (map (lambda (k) (* (pick '(1 -1)) (uniform 20 60))) (iota (- legs 1))))
         (path (let loop ((p box) (h first-heading) (bends (cons 0 bends)) (out (list box)))
                 (if (null? bends)
                     (reverse out)
                     (let* ((h (+ h (car bends)))
                            (q (towards p h (uniform 1000 3000)))
                            (q (list (round-mm (car q)) (round-mm (cadr q)))))
                       (loop q h (cdr bends) (cons q out))))))
         (box-heading (round-mm (+ (heading-to box (cadr path)) (uniform -15 15)))))
    (list w d side mass box-heading path bends (draw-robots w d side path 4))))

;; Four robots, (NAME X Y HEADING WHERE) each, WHERE the words for where it
;; starts: each drawn again, up to 40 times, until it stands clear of the
;; walls, the others and the box's way (robot-trouble).
(define (draw-robots w d side path n)
  (let ((box (car path)) (first-heading (heading-to (car path) (cadr path))))
    (define (draw-one name)
      (let* ((where (pick '(behind left right ahead)))
             (far? (< (draw!) 0.5))
             (mm (+ (/ side 2) (if far? (uniform 2200 3800) (uniform 1000 1800))))
             (toward (+ first-heading
                        (case where ((behind) 180) ((left) 90) ((right) -90) (else 0))
                        (uniform -25 25)))
             (p (towards box toward mm)))
        (list name (round-mm (car p)) (round-mm (cadr p)) (round-mm (uniform -180 180))
              (string-append (symbol->string where) (if far? ", far" ", near")))))
    (let loop ((names robot-names) (k n) (out '()))
      (if (= k 0)
          (reverse out)
          (let ((name (pick names)))
            (let again ((tries 1))
              (let ((r (draw-one name)))
                (if (or (= tries 40) (not (robot-trouble r w d side path out)))
                    (loop (delete name names) (- k 1) (cons r out))
                    (again (+ tries 1))))))))))

;;; Refusals

;; What is wrong with where robot r stands, or #f: on or against a wall or
;; outside the room, on another of robots, or where the box will pass (the
;; spare and the watcher stay where they are).  Behind the box at its start
;; is out of its way.
(define (robot-trouble r w d side path robots)
  (let* ((at (list (cadr r) (caddr r))) (name (symbol->string (car r)))
         (sweep (+ (* (/ side 2) (sqrt 2)) 200))
         (c (clearance at w d)) (mm (path-distance at path))
         (other (find (lambda (o) (< (distance at (list (cadr o) (caddr o)))
                                     (+ radius radius 150)))
                      robots)))
    (cond ((< c (+ radius 100))
           (string-append "the robot " name " (" (list-ref r 4) ") stands " (mm-words c)
                          " from a wall, or outside the room"))
          (other (string-append "the robots " name " and " (symbol->string (car other))
                                " stand on each other"))
          ((and (< mm (+ sweep radius 100))
                (not (behind-start? at path (+ (/ side 2) radius 200))))
           (string-append "the robot " name " (" (list-ref r 4) ") stands " (mm-words mm)
                          " from the box's path, in its way"))
          (else #f))))

;; Why the team cannot do the layout, or #f.  The box, turned any way, and
;; its pushers behind it must keep off the walls all along the path; a
;; pusher needs room behind the box at the start to come up to it, along
;; the box's axis from 250 mm behind its place; and each robot must stand
;; clear (robot-trouble).
(define (refusal layout)
  (let-values (((w d side mass box-heading path bends robots) (apply values layout)))
    (let* ((half (/ side 2))
           (sweep (+ (* half (sqrt 2)) 200))           ; the box turned, and a margin
           (behind (+ half radius 40))                 ; a pusher's place
           (legs (map list (drop-right path 1) (cdr path)))
           (names (cons "the box's start"
                        (map (lambda (i) (if (= i (length bends)) "the goal" "a bend"))
                             (iota (+ (length bends) 1))))))
      (or (any (lambda (p k)
                 (and (< (clearance p w d) sweep)
                      (string-append "the path's point " (point-words p) " (" k ") is "
                                     (mm-words (clearance p w d)) " from a wall; the box"
                                     " needs " (mm-words sweep))))
               path names)
          ;; Where each pusher stands along each leg, and at the start the
          ;; nearest point it comes up from (box-move.scm's staging), 250 mm
          ;; further back, clear of the sonar's echoes of the wall.
          (any (lambda (leg)
                 (let ((h (heading-to (car leg) (cadr leg))))
                   (any (lambda (p back need what)
                          (any (lambda (o)
                                 (let ((q (towards (towards p (+ h 180) back) (+ h 90) o)))
                                   (and (< (clearance q w d) need)
                                        (string-append "a pusher's " what " behind the box at "
                                                       (point-words p) ", " (point-words q)
                                                       ", is " (mm-words (clearance q w d))
                                                       " from a wall; it needs "
                                                       (mm-words need)))))
                               '(-170 170)))
                        (list (car leg) (cadr leg) (car leg))
                        (list behind behind (+ behind 250))
                        (list (+ radius 100) (+ radius 100) (+ radius 170))
                        '("place" "place" "way in"))))
               legs)
          (let loop ((rs robots) (before '()))
            (and (pair? rs)
                 (or (robot-trouble (car rs) w d side path before)
                     (loop (cdr rs) (cons (car rs) before)))))))))

;; Whether p lies behind the box at the path's start, out of its way.
(define (behind-start? p path room)
  (let* ((a (car path)) (h (heading-to a (cadr path)))
         (dx (- (car p) (car a))) (dy (- (cadr p) (cadr a))))
    (< (+ (* dx (cos (* h degrees))) (* dy (sin (* h degrees)))) (- room))))

(define (mm-words x) (string-append (number->string (round-mm x)) " mm"))
(define (point-words p)
  (string-append "(" (number->string (round-mm (car p))) " "
                 (number->string (round-mm (cadr p))) ")"))

;;; Writing it down

(define (write-lab dir seed layout code)
  (let-values (((w d side mass box-heading path bends robots) (apply values layout)))
    (call-with-output-file (string-append dir "/lab.scm")
      (lambda (out)
        (define (line . parts) (for-each (lambda (x) (display x out)) parts) (newline out))
        (line ";;; A box-moving lab drawn by tools/box-layout.scm from seed " seed ".")
        (line "(lab box-room-" seed)
        (line "  (port-base 7300)")
        (line "  (key-file \"box.key\")")
        (line "  (code \"path.scm\" \"" code "\")")
        (line "  (heartbeat 0.5)")
        (for-each (lambda (r)
                    (line "  (aspace " (car r) "              ; " (list-ref r 4))
                    (line "    (robot (pose " (cadr r) " " (caddr r) " " (cadddr r) "))")
                    (line "    (capabilities mobile fiducial))"))
                  robots)
        (line "  (world")
        (line "    (wall " (- w) " " (- d) " " w " " (- d) ")")
        (line "    (wall " w " " (- d) " " w " " d ")")
        (line "    (wall " w " " d " " (- w) " " d ")")
        (line "    (wall " (- w) " " d " " (- w) " " (- d) ")")
        (line "    (box " (car (car path)) " " (cadr (car path)) " " side " " side " "
              box-heading " " mass "))")
        (line "  (simulator (speed 2)))")))
    (call-with-output-file (string-append dir "/path.scm")
      (lambda (out)
        (display ";;; The box's path and side, as a user tells them (tools/box-layout.scm).\n" out)
        (write `(define box-path ',path) out)
        (newline out)
        (write `(define box-side ,side) out)
        (newline out)))))

(define (describe seed layout)
  (let-values (((w d side mass box-heading path bends robots) (apply values layout)))
    (string-append
     "box-layout: seed " (number->string seed) ": a room " (number->string (* 2 w))
     " by " (number->string (* 2 d)) " mm; a box " (number->string side) " mm, "
     (number->string mass) " kg, at " (point-words (car path)) " heading "
     (number->string box-heading) "; its path "
     (apply string-append (map (lambda (p) (string-append (point-words p) " ")) (cdr path)))
     "(" (number->string (- (length path) 1)) " legs, bending "
     (apply string-append
            (map (lambda (b) (string-append (if (> b 0) "left " "right ")
                                            (number->string (round-mm (abs b))) " "))
                 bends))
     "degrees); robots "
     (apply string-append
            (map (lambda (r) (string-append (symbol->string (car r)) " " (list-ref r 4)
                                            " " (point-words (at-of r)) "; "))
                 robots)))))
(define (at-of r) (list (cadr r) (caddr r)))

;; When a fault run kills a pusher, wall seconds after step 1: while the
;; box is in the first half of its way, which at the lab's twice real time
;; it goes at some 400 mm a wall second.
(define (fault-after layout)
  (let* ((path (list-ref layout 5))
         (mm (fold + 0 (map distance (drop-right path 1) (cdr path)))))
    (/ (round (* 10 (uniform 1 (+ 1 (/ mm 900))))) 10)))

(define (main args)
  (if (not (<= 2 (length args) 3))
      (begin (display "usage: box-layout.scm SEED DIR [CODE-FILE]\n" (current-error-port))
             (exit 2)))
  (let* ((seed (string->number (car args))) (dir (cadr args))
         (top (string-append (current-directory) "/"))
         (code (if (= (length args) 3) (caddr args) "examples/box-move.scm"))
         (code (if (char=? (string-ref code 0) #\/) code (string-append top code))))
    (if (not (and seed (exact-integer? seed) (>= seed 0)))
        (begin (display "box-layout.scm: SEED must be a whole number\n" (current-error-port))
               (exit 2)))
    (seed! seed)
    (let* ((layout (draw-layout)) (why (refusal layout)))
      (cond (why
             (display (string-append "box-layout: seed " (number->string seed)
                                     ": refused: " why "\n"))
             (flush-output-port)
             (exit 3))
            (else
             (create-directory* dir)
             (write-lab dir seed layout code)
             (display (describe seed layout))
             (newline)
             (display (string-append "box-layout: fault " (pick '("inside" "outside"))
                                     " after "
                                     (number->string (fault-after layout))
                                     " s\n"))
             (flush-output-port)
             (exit 0))))))

(main (cdr (command-line)))
