;;; box-lab.scm's task with no spare: the same room, box and path, and only
;;; the two pushers and the watcher, so that a pusher lost is not replaced
;;; and the other must finish alone (docs/box-move.md, "No spare").
;;;   make demo-box BOX_LAB=examples/box-lab-alone.scm FAULT=1

(lab box-room-alone
  (port-base 7700)
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
  (world
    (wall -4000 -3000  4000 -3000)
    (wall  4000 -3000  4000  3000)
    (wall  4000  3000 -4000  3000)
    (wall -4000  3000 -4000 -3000)
    (box -1500 0 600 600 0))
  (simulator (speed 2)))
