;;;; The lab file (docs/lab-file.md): who is in the lab and where.  Every
;;;; peer reads the same file, so the lab needs no registry.

(define-record-type lab
  (make-lab name directory settings aspaces clauses)
  lab?
  (name lab-name)
  (directory lab-directory)
  (settings lab-settings)
  (aspaces lab-aspaces)
  (clauses lab-clauses))

;;> The radius of the lab's robots in millimetres: its b14 clause's, or
;;> the simulator's B14's (room.scm).
(define (lab-robot-radius lab)
  (robot-radius (lab-clauses lab)))

;;> The lab file's top-level clause \scheme{(key ...)}, or #f.
(define (lab-clause lab key)
  (clause key (lab-clauses lab)))

;;> One address space of the lab file: \var{clauses}, those later layers
;;> read, and \var{form}, its whole clause, for errors to name its line.
(define-record-type lab-aspace
  (make-lab-aspace uid index host port clauses form)
  lab-aspace?
  (uid lab-aspace-uid)
  (index lab-aspace-index)
  (host lab-aspace-host)
  (port lab-aspace-port)
  (clauses lab-aspace-clauses)
  (form lab-aspace-form))

(define (clause key clauses)
  (find (lambda (c) (and (pair? c) (eq? (car c) key))) clauses))

(define (clause-value key clauses default)
  (cond ((clause key clauses) => cadr) (else default)))

;;> The clause \scheme{(key ...)} of an address space, or #f.
(define (lab-aspace-clause a key)
  (clause key (lab-aspace-clauses a)))

;;> The lab's port base: MURDOCH_PORT_BASE, else its port-base.
(define (lab-port-base lab)
  (settings-port-base (lab-settings lab)))

;;> The port plan: what listens at port-base + offset (+ its index for an
;;> address space or a robot); sim/lab.c gives trip servers the same.
(define port-plan
  '((aspace . 0)                        ; address space i
    (trip . 100)                        ; robot i's trip server
    (view-peer . 147)                   ; the live view's address space
    (view . 148)                        ; the live view's page
    (multicast . 149)                   ; the group, unless the lab names one
    (face-trip . 150)))                 ; robot i's B14 behind its ROS 2 face,
                                        ; when MURDOCH_ROS2=1 (docs/ros2.md)

;;> The port of \var{what} in the port plan from port base \var{base}, and
;;> \var{index} for an address space's or a robot's.
(define (planned-port base what . index)
  (+ base (cdr (assq what port-plan)) (if (pair? index) (car index) 0)))

;;> The port of \var{what} in the port plan of \var{lab}.
(define (lab-planned-port lab what . index)
  (apply planned-port (lab-port-base lab) what index))

;;> The port base where no lab file is read (murdoch replay).
(define (unread-lab-port-base)
  (settings-port-base
   (list (cons 'port-base (setting-default (setting-named 'port-base))))))

(define (settings-port-base settings)
  (cond ((get-environment-variable "MURDOCH_PORT_BASE") => string->number)
        (else (cdr (assq 'port-base settings)))))

;;> A guest's port: 0, a free one the kernel chooses, which the guest says
;;> in its hellos (docs/architecture.md says why not one by process id).
(define (lab-guest-port lab) 0)

;;> Reads the lab file at \var{path}; errors name the file, line and fault.
(define (read-lab path)
  (let* ((source (lab-source path))
         (data (car source)))
    (parameterize ((clause-lines (cdr source)))
      (cond ((null? data)
             (error (string-append path ": the file is empty; a lab file holds one"
                                   " (lab NAME CLAUSE ...) form")))
            ((pair? (cdr data))
             (lab-file-error path (car (cadr data))
                             (string-append "a second form; a lab file holds one"
                                            " (lab NAME CLAUSE ...) form")))
            ((not (let ((form (car (car data))))
                    (and (pair? form) (eq? (car form) 'lab) (pair? (cdr form))
                         (symbol? (cadr form)) (list? (cddr form)))))
             (lab-file-error path (car (car data))
                             "a lab file holds one (lab NAME CLAUSE ...) form"))
            (else (parse-lab path (car (car data))))))))

;; The lab file this process read last, kept for its forks (docs/speed.md).
(define-record-type lab-read
  (make-lab-read path text source)
  lab-read?
  (path lab-read-path)
  (text lab-read-text)
  (source lab-read-source))

(define *lab-read* #f)

(define (lab-source path)
  (let ((text (guard (e ((file-error? e) #f)) (file->string path)))
        (last *lab-read*))
    (cond ((not text) (read-source path))
          ((and last (equal? path (lab-read-path last)) (string=? text (lab-read-text last)))
           (lab-read-source last))
          (else (let ((source (read-source-port path (open-input-string text))))
                  (set! *lab-read* (make-lab-read path text source))
                  source)))))

(define (parse-lab path form)
  (let* ((clauses (cddr form))
         (settings (read-settings path clauses))
         (base (settings-port-base settings))
         (interface (cdr (assq 'interface settings)))
         (lab (make-lab (cadr form) (path-directory path) settings
                        (let loop ((cs clauses) (i 0) (acc '()))
                          (cond
                           ((null? cs) (reverse acc))
                           ((and (pair? (car cs)) (eq? (caar cs) 'aspace))
                            (loop (cdr cs) (+ i 1)
                                  (cons (parse-aspace path (car cs) i base interface)
                                        acc)))
                           (else (loop (cdr cs) i acc))))
                        clauses)))
    (check-lab path lab)
    (check-room path clauses)
    lab))

;; What no one clause shows: two address spaces of one name, two things on
;; one port, a missing code file; the later of two is named.
(define (check-lab path lab)
  (let loop ((as (lab-aspaces lab)))
    (when (pair? as)
      (cond ((find (lambda (b) (eq? (lab-aspace-uid b) (lab-aspace-uid (car as))))
                   (cdr as))
             => (lambda (b)
                  (lab-file-error
                   path (lab-aspace-form b)
                   (string-append "two address spaces of this name: the other"
                                  (line-words (lab-aspace-form (car as))))))))
      (loop (cdr as))))
  (let loop ((ports (lab-ports lab)))
    (when (pair? ports)
      (cond ((find (lambda (p) (= (listener-port p) (listener-port (car ports))))
                   (cdr ports))
             => (lambda (p)
                  (lab-file-error path (listener-clause p)
                                  (string-append
                                   "two things on port "
                                   (number->string (listener-port p)) ": "
                                   (listener-what (car ports))
                                   (line-words (listener-clause (car ports)))
                                   ", and " (listener-what p)
                                   " (address spaces listen at port-base + i, robots'"
                                   " trip servers at port-base + 100 + i)")))))
      (loop (cdr ports))))
  (for-each (lambda (file)
              (if (not (file-exists? (lab-path lab file)))
                  (lab-file-error path (clause 'code (lab-clauses lab))
                                  (string-append "no such file " file))))
            (lab-setting lab 'code)))

;; What listens on a port of the lab, and the clause that puts it there.
(define-record-type listener
  (make-listener port what clause)
  listener?
  (port listener-port)
  (what listener-what)
  (clause listener-clause))

;; Every listener of the lab's address spaces and robots, in file order.
(define (lab-ports lab)
  (append-map
   (lambda (a)
     (let ((name (symbol->string (lab-aspace-uid a)))
           (form (lab-aspace-form a)))
       (cons (make-listener (lab-aspace-port a) (string-append "the address space " name)
                            form)
             (if (lab-aspace-clause a 'robot)
                 (list (make-listener (lab-trip-port lab a)
                                      (string-append "the trip server of the robot " name)
                                      form))
                 '()))))
   (lab-aspaces lab)))

(define (parse-aspace path form index base interface)
  (let ((clauses (cddr form)))
    (make-lab-aspace (cadr form) index
                     (clause-value 'host clauses interface)
                     (clause-value 'port clauses (planned-port base 'aspace index))
                     clauses form)))

(define (path-directory path)
  (let loop ((i (- (string-length path) 1)))
    (cond ((< i 0) ".")
          ((char=? (string-ref path i) #\/)
           (if (zero? i) "/" (substring path 0 i)))
          (else (loop (- i 1))))))

;;> A path named in the lab file, which is relative to the file.
(define (lab-path lab file)
  (if (and (> (string-length file) 0) (char=? (string-ref file 0) #\/))
      file
      (string-append (lab-directory lab) "/" file)))

;;> The address space of the lab named \var{uid}, or #f.
(define (lab-aspace-by-uid lab uid)
  (find (lambda (a) (eq? (lab-aspace-uid a) uid)) (lab-aspaces lab)))

;;> The port of robot \var{a}'s trip server: its trip-port or port-base + 100 + index.
(define (lab-trip-port lab a)
  (robot-setting a 'trip-port (lab-planned-port lab 'trip (lab-aspace-index a))))

;;> The host of robot \var{a}'s trip server: its trip-host, when the
;;> simulator runs elsewhere, else its address space's host.
(define (lab-trip-host lab a)
  (robot-setting a 'trip-host (lab-aspace-host a)))

(define (robot-setting a key default)
  (let ((robot (lab-aspace-clause a 'robot)))
    (cond ((and robot (find (lambda (c) (and (pair? c) (eq? (car c) key) (pair? (cdr c))))
                            (cdr robot)))
           => cadr)
          (else default))))

;;> The uids of the lab's robots, in file order.
(define (lab-robots lab)
  (map lab-aspace-uid
       (filter (lambda (a) (lab-aspace-clause a 'robot)) (lab-aspaces lab))))
