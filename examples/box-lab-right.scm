;;; box-lab.scm's task on another layout: the box starts in the room's
;;; south-east and its path (box-path-right.scm) goes west and bends right;
;;; the box is twice as heavy; the pushers stand east of it and the spare
;;; in the north-east corner.
;;;   make demo-box BOX_LAB=examples/box-lab-right.scm [FAULT=1|2]

(lab box-room-right
  (port-base 7500)
  (key-file "box.key")
  (code "box-path-right.scm" "box-move.scm")
  (heartbeat 0.5)
  (aspace hopper
    (robot (pose 3300 -800 180))
    (capabilities mobile fiducial))
  (aspace lovelace
    (robot (pose 3300 -1700 180))
    (capabilities mobile fiducial))
  (aspace noether
    (robot (pose 600 1200 -90))
    (capabilities mobile fiducial))
  (aspace turing
    (robot (pose 3300 2300 180))
    (capabilities mobile fiducial))
  (world
    (wall -4000 -3000  4000 -3000)
    (wall  4000 -3000  4000  3000)
    (wall  4000  3000 -4000  3000)
    (wall -4000  3000 -4000 -3000)
    (box 2200 -1200 600 600 0 10))
  (simulator (speed 2)))
