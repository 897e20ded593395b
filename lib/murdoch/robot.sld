;;> The robot: the B14's primitives over trip.

(define-library (murdoch robot)
  (export trip-timeout trip-motion-timeout trip-connect set-current-robot!
          trip-error? trip-error-code im goto-xy goto-goal rotate translate
          angle-to-heading set-velocity stop-base reckon robot-time
          set-reckon-position! set-reckon-heading! sonar-start sonar-stop
          sonar-read ir-read bumpers-read skirt-read buttons-read lights say
          battery-voltage tethered? set-tether! fiducials fiducial-id
          fiducial-range fiducial-bearing fiducial-orientation safe-im
          safe-battery-voltage safe-reckon workstation-position)
  (import (murdoch robot trip)))
