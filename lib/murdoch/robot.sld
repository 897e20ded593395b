;;> The robot: the B14's primitives over trip.
;;> Its members are each a library of their own in robot/.

(define-library (murdoch robot)
  (export trip-connect trip-close trip-request trip-connection? trip-timeout
          trip-motion-timeout current-robot set-current-robot! trip-error?
          trip-error-robot trip-error-code trip-error-text im goto-xy goto-goal rotate
          translate angle-to-heading set-velocity stop-base reckon robot-time
          set-reckon-position! set-reckon-heading! sonar-start sonar-stop sonar-read
          ir-read bumpers-read skirt-read buttons-read lights say battery-voltage
          tethered? set-tether! fiducials fiducial-id fiducial-range fiducial-bearing
          fiducial-orientation safe-im safe-battery-voltage safe-reckon
          workstation-position split-words)
  (import (murdoch robot trip)))
