;;;; Why a task found not enough takers: who could have taken each
;;;; component and why none did, asked afresh once the negotiation has
;;;; given up, each capable robot answering the holders of its exclusive
;;;; subjects, and the lab file saying who should have answered.

;;> Writes to \var{port} why task \var{task-name} found no takers: for
;;> each of \var{layouts} (a component's (EXCLUSIVE SHARED) subjects), the
;;> address spaces capable of it, each free, held (and by which
;;> reservation, TASK@POSER/N) or away.
(define (explain-no-takers task-name layouts port)
  (let ((lines (explain-components layouts)))
    (write-string (string-append "pose-task: not enough takers for "
                                 (name task-name) ":\n"
                                 (apply string-append (explanation-lines lines))
                                 (too-few-line layouts (map explanation-free lines)))
                  port)
    (flush-output-port port)))

;;> What is known of one layout's takers: who could take it and why none
;;> did (its line, as explain-no-takers writes it for the component
;;> numbered i: \scheme{(explanation-line e i)}); free and capable are the
;;> uids of the live address spaces capable of it that are free, and all
;;> of them.  The number is the caller's, for a poser's look explains each
;;> layout once for all its waiting tasks' components.
(define-record-type explanation
  (make-explanation needs free capable)
  explanation?
  (needs explanation-needs)
  (free explanation-free)
  (capable explanation-capable))

;;> The line of explanation \var{e} for the component numbered \var{i}.
(define (explanation-line e i)
  (string-append "  component " (number->string i) " " (explanation-needs e) "\n"))

;;> The lines of \var{explanations}, one a component, numbered from 1.
(define (explanation-lines explanations)
  (map explanation-line explanations (iota (length explanations) 1)))

;;> An explanation for each of \var{layouts}, in order: one request of
;;> the whole lab, each address space answering for every layout at once
;;> (takers-here), so that a look of many components, or of a poser's
;;> many waiting tasks, costs one round of the lab, not one a component.
(define (explain-components layouts)
  (let* ((answers (request 'all takers-here layouts))
         (live (map car answers)))
    (map (lambda (i layout)
           (explain-component
            layout live
            (filter-map (lambda (a)
                          (let ((statuses (list-ref (cadr a) (- i 1))))
                            (and statuses (list (car a) statuses))))
                        answers)))
         (iota (length layouts) 1) layouts)))

;;> What an address space answers explain-components: for each of
;;> \var{layouts}, the statuses of its exclusive subjects when it has
;;> every subject of the layout, else #f.
(define (takers-here layouts)
  (map (lambda (layout)
         (and (addressed-here? (apply append layout)) (map topic-status (car layout))))
       layouts))

;; What a layout needs and who could take it, the robots free for it,
;; and those capable; answers, (UID STATUSES) of each address space that
;; has its subjects.
(define (explain-component layout live answers)
  (let* ((exclusive (car layout))
         (answers (in-lab-order answers))
         (silent (remove (lambda (uid) (assq uid answers))
                         (file-capable (apply append layout)))))
    (make-explanation
     (string-append
      "needs " (name layout) ": "
      (if (and (null? answers) (null? silent))
          "no address space of the lab is capable of it"
          (join (append (map robot-state answers)
                        (map (lambda (uid) (silent-state uid live)) silent)))))
     (filter-map (lambda (a) (and (free? a) (car a))) answers)
     (map car answers))))

;; When each component that needs a robot to itself has a free one, but
;; there are fewer free robots than such components, a line that says so.
(define (too-few-line layouts frees)
  (let* ((needing (filter-map (lambda (l f) (and (pair? (car l)) f)) layouts frees))
         (free (delete-duplicates (apply append needing))))
    (if (and (every pair? needing) (< (length free) (length needing)))
        (string-append "  " (number->string (length needing))
                       " components each need a robot of their own; "
                       (if (= 1 (length free))
                           "1 capable robot is free\n"
                           (string-append (number->string (length free))
                                          " capable robots are free\n")))
        "")))

(define (holders answer)
  (delete-duplicates (filter (lambda (s) (and s (not (null? s)))) (cadr answer))))

(define (free? answer) (null? (holders answer)))

;; (UID STATUSES): free when no exclusive subject is held, else who holds
;; them.
(define (robot-state answer)
  (string-append (name (car answer))
                 (if (free? answer)
                     " free"
                     (string-append " held by " (join (map name (holders answer)))))))

;; Answers (UID ...) in the order the lab file gives the address spaces,
;; guests last.
(define (in-lab-order answers)
  (let ((order (map lab-aspace-uid (lab-aspaces (current-lab)))))
    (append (filter-map (lambda (uid) (assq uid answers)) order)
            (remove (lambda (a) (memq (car a) order)) answers))))

;; A capable robot that did not answer: away, or there but without one of
;; the subjects now (not idle, say, or tethered).
(define (silent-state uid live)
  (string-append (name uid)
                 (if (memq uid live) " not subscribed to all of them now" " away")))

;; The lab's address spaces whose capabilities, as the lab file gives them
;; (with their uid, all, and the subjects monitors add), cover subjects.
(define (file-capable subjects)
  (filter-map
   (lambda (a)
     (let ((has (append (list (lab-aspace-uid a) 'all 'idle 'untethered)
                        (cond ((lab-aspace-clause a 'capabilities) => cdr)
                              (else '())))))
       (and (every (lambda (s) (memq s has)) subjects)
            (lab-aspace-uid a))))
   (lab-aspaces (current-lab))))

(define (name x)
  (if (symbol? x) (symbol->string x) (call-with-output-string (lambda (o) (write x o)))))

(define (join strings)
  (if (null? strings)
      ""
      (fold (lambda (s acc) (string-append acc ", " s)) (car strings) (cdr strings))))
