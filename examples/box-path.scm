;;; The box's path (box-lab.scm): the waypoints its centre goes through,
;;; in the room's millimetres, from where it starts to the goal, and the
;;; box's size: what the user tells the task.  The box has arrived when its
;;; centre is within 300 mm of the goal and its heading within 20 degrees
;;; of the last leg's, a square box's heading being the same every quarter
;;; turn.  box-move.scm, the lab's next code file, moves it; `make demo-box`
;;; and tests/box-move-test.scm judge where it ended (box-judge.scm).

(define box-path '((-1500 0) (300 0) (1800 900)))

;; The box's side, mm: the fiducial finder tells where the box is, not how
;; big it is.
(define box-side 600)
