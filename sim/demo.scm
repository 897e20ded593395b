;;; make demo: the dual-sonar task of thesis §4.2.4 acted out on the
;;; simulator: moseley takes a sonar reading at (300 200) facing 0, ernst at
;;; (-1000 200) facing 90, both at once, as pose-task would send them.
;;; MURDOCH_PORT_BASE says where sim/b14 serves the Tulane lab.
(import (scheme base) (scheme write) (scheme cxr) (scheme process-context) (srfi 18)
        (murdoch trip-client))

(define base (string->number (get-environment-variable "MURDOCH_PORT_BASE")))

;; The thesis's dual-sonar-task-proc-maker-1, word for word.
(define (sonar-task coords)
  (lambda ()
    (sonar-start)
    (goto-xy (list (car coords) (cadr coords)))
    (rotate 'by (angle-to-heading (caddr coords)))
    (sonar-stop)
    (sonar-read)))

(define (on-robot port target)
  (make-thread
   (lambda ()
     (parameterize ((current-robot (trip-connect "127.0.0.1" port)))
       (im)
       (say "going to" (list (car target) (cadr target)))
       (lights 1 0 0 0)
       (let ((reading ((sonar-task target))))
         (say "sonar ahead reads" (car reading) "millimetres")
         (lights 0 0 0 1)
         reading)))))

(define moseley (on-robot (+ base 100) '(300 200 0)))
(define ernst (on-robot (+ base 101) '(-1000 200 90)))
(thread-start! moseley)
(thread-start! ernst)
(for-each (lambda (name t)
            (display name) (display ": ") (write (thread-join! t)) (newline))
          '("moseley" "ernst") (list moseley ernst))
