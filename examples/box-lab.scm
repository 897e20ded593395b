;;; A team moves a box (thesis §1.2; MURDOCH 2002's box-pushing): two
;;; pushers and a watcher, with a spare robot for when a pusher fails.
;;; The box starts at (-1500 0); its path (box-path.scm) bends at (300 0)
;;; and ends at (1800 900).
;;; Every robot has the fiducial finder and sees the box only through it.

(lab box-room
  (port-base 7300)
  (key-file "box.key")
  (code "box-path.scm" "box-move.scm")
  (heartbeat 0.5)
  (aspace moseley
    (robot (pose -2700 400 0))
    (capabilities mobile fiducial))
  (aspace ernst
    (robot (pose -2700 -400 0))
    (capabilities mobile fiducial))
  (aspace troy
    (robot (pose 0 2500 -90))
    (capabilities mobile fiducial))
  (aspace kiwi
    (robot (pose -3300 -2300 0))
    (capabilities mobile fiducial))
  (world
    (wall -4000 -3000  4000 -3000)
    (wall  4000 -3000  4000  3000)
    (wall  4000  3000 -4000  3000)
    (wall -4000  3000 -4000 -3000)
    (box -1500 0 600 600 0))
  (simulator (speed 2)))
