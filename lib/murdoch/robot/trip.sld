;;> The MOVER robot primitives over trip (docs/trip-protocol.md), acting
;;> on \scheme{(current-robot)}'s connection.
(define-library (murdoch robot trip)
  (export trip-connect trip-close trip-request trip-connection? trip-timeout
          trip-motion-timeout
          current-robot set-current-robot!
          trip-error? trip-error-robot trip-error-code trip-error-text
          im goto-xy goto-goal rotate translate angle-to-heading set-velocity stop-base
          reckon set-reckon-position! set-reckon-heading! robot-time
          sonar-start sonar-stop sonar-read ir-read bumpers-read skirt-read
          buttons-read lights say battery-voltage tethered? set-tether! fiducials
          fiducial-id fiducial-range fiducial-bearing fiducial-orientation
          safe-im safe-battery-voltage safe-reckon workstation-position
          split-words)
  (import (scheme base) (scheme write) (srfi 18) (srfi 69) (srfi 151)
          (only (chibi) make-exception exception? exception-kind exception-irritants
                call-with-output-string)
          (murdoch code) (murdoch wire) (only (murdoch lab) lab-default)
          (only (murdoch sys) with-lock make-mailbox mailbox-put! mailbox-take
                take-mailbox! take-all-mailboxes! monotonic-seconds port-wait!))
  (include "trip.scm"))
