;;;; The task layer's parts of the node (lab/node.scm): each file of
;;;; task/ that keeps state keeps it in its own part.

;;> Makes this node's task parts, empty: the teams held, poses
;;> negotiating and components run here, the tasks posed, waiting and
;;> handed here, the poser's look, and the robot's offers.
(define (open-tasks!)
  (open-teams!)
  (open-poses!)
  (open-runs!)
  (open-posed!)
  (open-line!)
  (open-looking!)
  (open-offering!)
  (open-handing!))
