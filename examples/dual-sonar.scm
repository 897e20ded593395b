;;; The dual-sonar task of the thesis (§4.2.4, Figure 4.6): two robots with
;;; sonar each drive to a target and take a sonar reading there, while an
;;; idle machine sorts 100 random numbers.  Every address space loads this
;;; file (the lab's code clause), so these procedures travel by name.

(define (dual-sonar-task)
  (let ((target1 '(300 200 0))
        (target2 '(-1000 200 90))
        (num 100))
    (list 'dual-sonar-task
          3
          (list
           (list (list 'mobile) (list 'sonar))
           (list (list 'mobile) (list 'sonar))
           (list '() (list 'idle)))
          (list
           (location-metric-maker target1)
           (location-metric-maker target2)
           load-metric)
          (list
           (sonar-task-proc-maker target1)
           (sonar-task-proc-maker target2)
           (random-number-task-proc-maker num)))))

;; coords is (x y theta): go there, face theta, and read the sonar ring.
(define (sonar-task-proc-maker coords)
  (lambda ()
    (sonar-start)
    (goto-xy (list (car coords) (cadr coords)))
    (rotate 'by (angle-to-heading (caddr coords)))
    (let ((ranges (sonar-read)))
      (sonar-stop)
      ranges)))

;; num is the length of the list to sort.
(define (random-number-task-proc-maker num)
  (lambda ()
    (sort-list
     (let loop ((num-left num))
       (if (zero? num-left)
           '()
           (cons ((make-maxrandom 100)) (loop (- num-left 1)))))
     <)))
