;;; The settings that are parameters, or the thesis's thresholds, of the
;;; layers above the lab: their defaults are the lab's table's, and an
;;; address space that joins a lab takes the lab file's values.
(import (scheme base) (chibi test)
        (murdoch) (only (murdoch robot) trip-timeout trip-motion-timeout)
        (only (murdoch lab) read-lab lab-setting lab-default)
        (murdoch cli command) (murdoch testing harness))

(test-begin "tunables")

(test "before a lab is joined, each parameter is its default in the lab's table"
    (map lab-default '(task-timeout trip-timeout trip-motion-timeout
                       pose-task-retries pose-task-backoff))
  (list (task-timeout) (trip-timeout) (trip-motion-timeout)
        (pose-task-retries) (pose-task-backoff)))

(define lab
  (make-test-lab '((task-timeout 60) (trip-timeout 2) (trip-motion-timeout 30)
                   (pose-task-retries 1) (pose-task-backoff 0.5)
                   (battery-charging 120) (battery-low 90) (load-threshold ".5"))))

(test "a bad value is the lab file's error, naming the setting" #t
  (let ((bad (make-test-lab '((pose-task-retries -1)))))
    (guard (e ((error-object? e)
               (remove-test-lab! bad)
               (text-contains? (error-object-message e) "pose-task-retries takes")))
      (read-lab (test-lab-file bad))
      #f)))

(join-lab (test-lab-file lab) 'tester 0)   ; a guest, on a port the kernel picks

(test "an address space that joins takes the lab file's values"
    '(60 2 30 1 0.5 120 90 ".5")
  (list (task-timeout) (trip-timeout) (trip-motion-timeout)
        (pose-task-retries) (pose-task-backoff)
        (battery-charging) (battery-low) (load-threshold)))

(test "parameterize still overrides the lab's value, for its extent" '(7 60)
  (list (parameterize ((task-timeout 7)) (task-timeout)) (task-timeout)))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
